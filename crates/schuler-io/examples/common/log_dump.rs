//! What the device-log dump examples (`ulog_dump`, `dataflash_dump`) share: every
//! record of a [`LogReader`] as one CSV line (kind, stream, values; the format their
//! doc gives), and the reader timed on a file.

use schuler_io::logs::{LogReader, LogRecord};
use std::io::Write;
use std::path::Path;

type DumpResult = Result<(), Box<dyn std::error::Error>>;

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

/// Prints the time scale, the streams, the reader's report (`report`) and every record.
pub fn dump<R: LogReader>(mut r: R, report: impl Fn(&R) -> String) -> DumpResult {
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
    writeln!(w, "# report {}", report(&r))?;
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

/// Reads `path` five times with `open`; prints bytes, records and the best pass's MB/s.
pub fn time<R, E>(path: &Path, open: impl Fn(&Path) -> Result<R, E>) -> DumpResult
where
    R: LogReader,
    E: std::error::Error + 'static,
{
    let bytes = std::fs::metadata(path)?.len();
    let mut best = f64::INFINITY;
    let mut records = 0usize;
    for _ in 0..5 {
        let t0 = std::time::Instant::now();
        let r = open(path)?;
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
