//! `schuler vertical`: the vertical channel, free or baro-aided, with faults and
//! prediction ([`schuler_run::vertical`]); where its files went, printed.

use schuler_run::vertical::{Args, run_and_write};

/// `schuler vertical`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let summary = run_and_write(&args)?;
    println!(
        "schuler vertical ({}): wrote {}",
        summary["mode"].as_str().unwrap_or("?"),
        args.out.display()
    );
    Ok(())
}
