//! Prints every record schuler's ArduPilot DataFlash reader reads from a `.bin` (or
//! `.bin.gz`) log, one CSV line each, the first two columns the record's kind and its
//! stream:
//!
//! ```text
//! imu,STREAM,t,dt,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z
//! gnss,STREAM,t,lat_deg,lon_deg,h,std_n,std_e,std_d,v_n,v_e,v_d,sv_n,sv_e,sv_d
//! baro,STREAM,t,h
//! ref,STREAM,t,lat_deg,lon_deg,h,v_n,v_e,v_d,roll,pitch,yaw
//! ```
//!
//! (empty columns where a record lacks a part), after `#` lines giving the time scale,
//! the streams and the reader's report. Numbers are in the shortest form that reads
//! back to the same f64. `crates/schuler-io/tests/pymavlink_check.py` compares them
//! with pymavlink's.
//!
//! `cargo run -p schuler-io --example dataflash_dump -- FILE`; `--time FILE…` instead
//! times the reader on each file (the best of five passes; bytes, records, MB/s).

use schuler_io::logs::dataflash::DataflashReader;
use schuler_io::logs::{LogReader, LogRecord};
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

#[path = "common/dump_cli.rs"]
mod dump_cli;

fn main() -> ExitCode {
    dump_cli::run("dataflash_dump", dump, time)
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

fn dump(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let mut r = DataflashReader::open(path)?;
    let out = std::io::stdout();
    let mut w = std::io::BufWriter::new(out.lock());
    writeln!(w, "# time_scale {:?}", r.time_scale())?;
    let mut lines = Vec::new();
    for item in r.by_ref() {
        lines.push(item?);
    }
    for (i, s) in r.streams().iter().enumerate() {
        writeln!(w, "# stream {i} {} {:?}", s.name, s.kind)?;
    }
    writeln!(w, "# report {:?}", r.report())?;
    for item in lines {
        let name = &r.streams()[item.stream].name;
        match item.record {
            LogRecord::Imu(s) => writeln!(
                w,
                "imu,{name},{},{},{},{},{},{},{},{}",
                s.t, s.dt, s.dtheta.x, s.dtheta.y, s.dtheta.z, s.dvel.x, s.dvel.y, s.dvel.z
            )?,
            LogRecord::Gnss(f) => {
                let (v, sv) = match f.vel {
                    Some((v, s)) => (
                        format!("{},{},{}", v.x, v.y, v.z),
                        format!("{},{},{}", s.x, s.y, s.z),
                    ),
                    None => (",,".to_owned(), ",,".to_owned()),
                };
                writeln!(
                    w,
                    "gnss,{name},{},{},{},{},{},{},{},{v},{sv}",
                    f.t,
                    f.pos.lat.to_degrees(),
                    f.pos.lon.to_degrees(),
                    f.pos.h,
                    f.pos_std.x,
                    f.pos_std.y,
                    f.pos_std.z
                )?;
            }
            LogRecord::Baro { t, h } => writeln!(w, "baro,{name},{t},{h}")?,
            LogRecord::Reference(r) => writeln!(
                w,
                "ref,{name},{},{},{},{},{},{},{},{},{},{}",
                r.t,
                opt(r.pos.map(|p| p.lat.to_degrees())),
                opt(r.pos.map(|p| p.lon.to_degrees())),
                opt(r.pos.map(|p| p.h)),
                opt(r.v_n.map(|v| v.x)),
                opt(r.v_n.map(|v| v.y)),
                opt(r.v_n.map(|v| v.z)),
                opt(r.att.map(|a| a.roll)),
                opt(r.att.map(|a| a.pitch)),
                opt(r.att.map(|a| a.yaw)),
            )?,
            LogRecord::Raw(_) | LogRecord::Ephemeris(_) => {}
        }
    }
    Ok(())
}

fn time(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let bytes = std::fs::metadata(path)?.len();
    let mut best = f64::INFINITY;
    let mut records = 0usize;
    for _ in 0..5 {
        let t0 = std::time::Instant::now();
        let r = DataflashReader::open(path)?;
        records = 0;
        for item in r {
            item?;
            records += 1;
        }
        best = best.min(t0.elapsed().as_secs_f64());
    }
    println!(
        "{}: {bytes} bytes, {records} records, {:.1} MB/s",
        path.display(),
        bytes as f64 / best / 1e6
    );
    Ok(())
}
