//! `schuler demo`: the second seed document's flight test re-enacted end to end
//! ([`schuler_run::demo`]), with a progress bar per task on stderr and the summary on
//! stdout.

use anyhow::Result;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use schuler_run::progress::{Progress, Task};
use std::path::PathBuf;

/// Arguments of `schuler demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Output directory.
    #[arg(long, default_value = "schuler-demo")]
    pub out: PathBuf,
    /// A shortened sortie (200 Hz, 5 min on the pad, 7 min of flight) and pole
    /// crossing (4 min) that run in seconds.
    #[arg(long)]
    pub quick: bool,
}

/// The demo's tasks as progress bars, one line each.
struct Bars(MultiProgress);

/// One task's bar.
struct Bar(ProgressBar);

impl Task for Bar {
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
    fn finish(&self) {
        self.0.finish();
    }
}

impl Progress for Bars {
    fn task(&self, name: &str, len: u64) -> Box<dyn Task> {
        let b = self.0.add(ProgressBar::new(len));
        b.set_style(
            ProgressStyle::with_template("{prefix:>28} [{bar:30}] {pos:>5}/{len} s  {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        b.set_prefix(name.to_string());
        Box::new(Bar(b))
    }
}

/// `schuler demo`.
pub fn run(args: DemoArgs) -> Result<()> {
    let bars = Bars(MultiProgress::with_draw_target(ProgressDrawTarget::stderr()));
    let summary = schuler_run::demo::run(&args.out, args.quick, &bars)?;
    bars.0.clear().ok();
    println!("{summary}");
    Ok(())
}
