//! Prints every observation of a RINEX observation file (plain, gzip or Hatanaka),
//! one per line: `time sat code value lli ssi`, the time as written (ISO 8601, the
//! header's time system), the code as the file names it (`C1C`, RINEX 2's `P2`), the
//! value in the shortest form that reads back to the same f64, blank indicators as
//! `-`. Events (flags 2–5) and cycle-slip records (flag 6) are left out.
//!
//! `cargo run -p schuler-io --example rinex_obs_dump -- FILE`; the observations of
//! `crates/schuler-io/tests/georinex_check.py` to compare with georinex's.
//!
//! `--time FILE…` instead reads each file into memory and times the reader on it (the
//! best of five passes; a gzip file is gunzipped first): bytes, epochs, observations,
//! MB/s.

use schuler_io::formats::rinex::obs::{Epoch, ObsReader};
use std::io::Write;
use std::process::ExitCode;

#[path = "common/dump_cli.rs"]
mod dump_cli;

fn main() -> ExitCode {
    dump_cli::run("rinex_obs_dump", dump, time)
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

/// Times the reader on `path`'s bytes in memory (gunzipped first when gzip).
fn time(path: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let mut bytes = std::fs::read(path)?;
    if bytes.starts_with(&[0x1f, 0x8b]) {
        let mut plain = Vec::new();
        std::io::Read::read_to_end(
            &mut flate2::read::MultiGzDecoder::new(&bytes[..]),
            &mut plain,
        )?;
        bytes = plain;
    }
    let mut best = f64::INFINITY;
    let (mut epochs, mut obs) = (0, 0);
    for _ in 0..5 {
        let t0 = std::time::Instant::now();
        let mut reader = ObsReader::new(&bytes[..], path)?;
        let mut epoch = Epoch::default();
        (epochs, obs) = (0, 0);
        while reader.read_epoch(&mut epoch)? {
            epochs += 1;
            obs += epoch.sats().map(|s| s.obs.len()).sum::<usize>();
        }
        best = best.min(t0.elapsed().as_secs_f64());
    }
    println!(
        "{}: {} bytes, {epochs} epochs, {obs} observations, best of 5 {best:.3} s, {:.1} MB/s",
        path.display(),
        bytes.len(),
        bytes.len() as f64 / best / 1e6
    );
    Ok(())
}
