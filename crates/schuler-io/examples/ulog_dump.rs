//! Prints every record schuler's ULog reader reads from a `.ulg` (or `.ulg.gz`) file,
//! one CSV line each, the first two columns the record's kind and its stream:
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
//! back to the same f64. `crates/schuler-io/tests/pyulog_check.py` compares them with
//! pyulog's.
//!
//! `cargo run -p schuler-io --example ulog_dump -- FILE`; `--time FILE…` instead times
//! the reader on each file (the best of five passes; bytes, records, MB/s).

use schuler_io::logs::ulog::UlogReader;
use std::path::Path;
use std::process::ExitCode;

#[path = "common/dump_cli.rs"]
mod dump_cli;
#[path = "common/log_dump.rs"]
mod log_dump;

fn main() -> ExitCode {
    dump_cli::run("ulog_dump", dump, time)
}

fn dump(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    log_dump::dump(UlogReader::open(path)?, |r| format!("{:?}", r.report()))
}

fn time(path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    log_dump::time(path, UlogReader::open)
}
