//! One module per `schuler` subcommand: each parses its arguments and wires library
//! calls to readers and writers.

pub mod align;
pub mod allan;
pub mod bag;
pub mod budget;
pub mod channel;
pub mod compare;
pub mod demo;
pub mod gnss;
pub mod inspect;
pub mod kf_gins;
pub mod montecarlo;
pub mod nav;
pub mod nav_bag;
pub mod nav_log;
pub mod platform;
pub mod simulate;
pub mod vertical;

/// `schuler nav`: a KF-GINS configuration (`--kf-gins-config`) runs as KF-GINS does
/// ([`kf_gins::run`]), anything else as [`nav::run`].
pub fn run_nav(args: schuler_run::nav::NavArgs) -> anyhow::Result<()> {
    schuler_run::interrupt::watch();
    match &args.kf_gins_config {
        Some(path) => kf_gins::run(
            path,
            &schuler_run::kf_gins::KfGinsOptions {
                report: args.report,
                nav_csv: args.nav_csv,
                gate: args.aiding.gate,
                gravity: args.gravity,
                propagation_interval: schuler_run::options::quantity(
                    "propagation-interval",
                    &args.aiding.propagation_interval,
                    schuler::units::Dimension::Time,
                )?,
            },
        ),
        None => nav::run(args),
    }
}
