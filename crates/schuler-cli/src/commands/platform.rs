//! `schuler platform`: lecture 22's systems on one trajectory
//! ([`schuler_run::platform`]); the table of their errors, printed.

use schuler_run::platform::{Args, run_and_write};

/// `schuler platform`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let table = run_and_write(&args)?;
    print!("{table}");
    println!("wrote {}", args.out.display());
    Ok(())
}
