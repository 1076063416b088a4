//! Keyword arguments as the CLI's flags: the Python layer turns `init_pos=(45, 7, 245)`
//! into `--init-pos=45.0,7.0,245.0` (exact `repr` of each float) and the CLI's own
//! parser reads them, so names, defaults, units and checks are the CLI's.

use anyhow::Result;
use clap::Parser;
use schuler_run::aided::AidingOptions;
use schuler_run::imu_input::ImuInputOptions;
use schuler_run::nav::NavArgs;

/// The IMU reader's options with the time window.
#[derive(Parser, Debug)]
#[command(name = "read_imu", no_binary_name = true)]
struct ImuFlags {
    #[command(flatten)]
    input: ImuInputOptions,
    /// Start time [s].
    #[arg(long)]
    start: Option<f64>,
    /// End time [s].
    #[arg(long)]
    end: Option<f64>,
}

/// The GNSS reader's options (the aiding flags that act on the fixes).
#[derive(Parser, Debug)]
#[command(name = "read_gnss", no_binary_name = true)]
struct GnssFlags {
    #[command(flatten)]
    aiding: AidingOptions,
}

/// `schuler nav`'s arguments from `flags`.
pub fn nav_args(flags: &[String]) -> Result<NavArgs> {
    schuler_run::campaign::navigate::nav_args(flags)
}

/// The IMU reader's options and time window from `flags`.
pub fn imu_options(flags: &[String]) -> Result<schuler_io::formats::ImuReadOptions> {
    let f = ImuFlags::try_parse_from(flags)?;
    f.input.read_options(f.start, f.end)
}

/// The aiding options from `flags` (`--gnss` among them).
pub fn aiding_options(flags: &[String]) -> Result<AidingOptions> {
    Ok(GnssFlags::try_parse_from(flags)?.aiding)
}
