//! Prints every observation of a RINEX observation file (plain, gzip or Hatanaka),
//! one per line: `time sat code value lli ssi`, the time as written (ISO 8601, the
//! header's time system), the code as the file names it (`C1C`, RINEX 2's `P2`), the
//! value in the shortest form that reads back to the same f64, blank indicators as
//! `-`. Events (flags 2–5) and cycle-slip records (flag 6) are left out.
//!
//! `cargo run -p schuler-io --example rinex_obs_dump -- FILE`; the observations of
//! `crates/schuler-io/tests/georinex_check.py` to compare with georinex's.

use schuler_io::formats::rinex::obs::{Epoch, ObsReader};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args_os().nth(1).map(PathBuf::from) else {
        eprintln!("usage: rinex_obs_dump FILE");
        return ExitCode::from(2);
    };
    match dump(&path) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

fn dump(path: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let mut reader = ObsReader::open(path)?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut epoch = Epoch::default();
    let indicator = |v: Option<u8>| v.map_or('-', |d| char::from(b'0' + d));
    while reader.read_epoch(&mut epoch)? {
        if !epoch.flag.has_measurements() {
            continue;
        }
        let time = epoch.time.format("%Y-%m-%dT%H:%M:%S%.f");
        for s in epoch.sats() {
            for o in s.obs {
                let code = reader
                    .header()
                    .column_name(s.sat.system, usize::from(o.code));
                writeln!(
                    out,
                    "{time} {} {code} {:?} {} {}",
                    s.sat,
                    o.value,
                    indicator(o.lli),
                    indicator(o.ssi)
                )?;
            }
        }
    }
    out.flush()?;
    Ok(())
}
