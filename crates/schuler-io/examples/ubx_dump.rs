//! Prints what the UBX reader reads from a log, one record per line, for
//! `crates/schuler-io/tests/pyubx2_check.py` to compare with pyubx2's decoding:
//!
//! - `PVT t lat_deg lon_deg h vN vE vD hAcc vAcc sAcc` (fixes; t in GPS seconds);
//! - `ATT t roll_deg pitch_deg yaw_deg` (NAV-ATT);
//! - `RAW week tow sat signal pr cp doppler cn0 pr_std cp_std do_std lock_ms half`
//!   (`-` for a value the measurement lacks);
//! - `IMU stream dt wx wy wz fx fy fz` (rates = increments / dt, FRD, rad/s and m/s²);
//! - `EPH sat iode iodc toe_week toe_sow` (decoded ephemerides);
//! - `COUNT stream n` for every stream at the end.
//!
//! Numbers in Rust's shortest round-trip form. `cargo run -p schuler-io --example
//! ubx_dump -- FILE`.
//!
//! `--time FILE…` instead reads each file into memory (gunzipped) and times the reader
//! on it: best of five passes, MB/s of the uncompressed log.

use schuler_io::logs::ubx::{UbxOptions, UbxReader};
use schuler_io::logs::{LogReader, LogRecord};
use std::io::{Read, Write};
use std::path::Path;
use std::process::ExitCode;

#[path = "common/dump_cli.rs"]
mod dump_cli;

fn main() -> ExitCode {
    dump_cli::run("ubx_dump", dump, time)
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |x| format!("{x:?}"))
}

fn dump(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let mut reader = UbxReader::open(path)?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    while let Some(item) = reader.next() {
        let item = item?;
        match &item.record {
            LogRecord::Gnss(f) => {
                let (v, s) = f.vel.expect("NAV-PVT carries a velocity");
                writeln!(
                    out,
                    "PVT {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?}",
                    f.t,
                    f.pos.lat.to_degrees(),
                    f.pos.lon.to_degrees(),
                    f.pos.h,
                    v.x,
                    v.y,
                    v.z,
                    f.pos_std.x,
                    f.pos_std.z,
                    s.x
                )?;
            }
            LogRecord::Reference(r) => {
                if let Some(a) = r.att {
                    writeln!(
                        out,
                        "ATT {:?} {:?} {:?} {:?}",
                        r.t,
                        a.roll.to_degrees(),
                        a.pitch.to_degrees(),
                        a.yaw.to_degrees()
                    )?;
                }
            }
            LogRecord::Raw(e) => {
                for m in &e.measurements {
                    let lock = m.lock.unwrap_or_default();
                    writeln!(
                        out,
                        "RAW {} {:?} {} {} {} {} {} {} {} {} {} {} {}",
                        e.t.week,
                        e.t.sow,
                        m.sat,
                        m.signal.rinex(),
                        opt(m.pseudorange),
                        opt(m.carrier_phase),
                        opt(m.doppler),
                        opt(m.cn0),
                        opt(m.pseudorange_std),
                        opt(m.carrier_phase_std),
                        opt(m.doppler_std),
                        lock.lock_time_ms.unwrap_or(0),
                        u8::from(lock.half_cycle)
                    )?;
                }
            }
            LogRecord::Imu(s) => {
                let w = s.dtheta / s.dt;
                let f = s.dvel / s.dt;
                writeln!(
                    out,
                    "IMU {} {:?} {:?} {:?} {:?} {:?} {:?} {:?}",
                    reader.streams()[item.stream].name,
                    s.dt,
                    w.x,
                    w.y,
                    w.z,
                    f.x,
                    f.y,
                    f.z
                )?;
            }
            LogRecord::Ephemeris(e) => writeln!(
                out,
                "EPH {} {} {} {} {:?}",
                e.sat, e.iode, e.iodc, e.toe.week, e.toe.sow
            )?,
            LogRecord::Baro { .. } => {}
        }
    }
    for (s, n) in reader.streams().iter().zip(reader.counts()) {
        writeln!(out, "COUNT {} {n}", s.name)?;
    }
    Ok(())
}

fn time(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let raw = std::fs::read(path)?;
    let bytes = if raw.starts_with(&[0x1f, 0x8b]) {
        let mut out = Vec::new();
        flate2::read::MultiGzDecoder::new(raw.as_slice()).read_to_end(&mut out)?;
        out
    } else {
        raw
    };
    let mut best = f64::INFINITY;
    let mut records = 0;
    for _ in 0..5 {
        let start = std::time::Instant::now();
        let input = Box::new(std::io::Cursor::new(bytes.clone()));
        let reader = UbxReader::new(path, input, bytes.len() as u64, UbxOptions::default());
        records = 0;
        for item in reader {
            item?;
            records += 1;
        }
        best = best.min(start.elapsed().as_secs_f64());
    }
    println!(
        "{}: {} bytes, {records} records, {:.0} MB/s",
        path.display(),
        bytes.len(),
        bytes.len() as f64 / best / 1e6
    );
    Ok(())
}
