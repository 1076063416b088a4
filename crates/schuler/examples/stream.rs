//! A live front end in a few lines: navigation samples and aids read one line at a time
//! from standard input (a pipe, a serial-port logger, a socket relay), pushed into the
//! library's session as they arrive, and every output epoch printed as soon as the
//! session emits it.
//!
//! ```sh
//! { awk '{print "imu", $0}' sim/imu.txt; awk '{print "gnss", $0}' sim/gnss.txt; } \
//!   | sort -s -g -k2 \
//!   | cargo run --release --example stream -- 45.07 7.68 245 0 0 10
//! ```
//!
//! Arguments: initial latitude, longitude [deg], height [m], roll, pitch, yaw [deg].
//! Input lines (whitespace separated, `#` comments):
//! - `imu t dθx dθy dθz dvx dvy dvz`: increments over (previous t, t] [rad, m/s], FRD;
//! - `gnss t lat lon h [σN σE σD]`: a position fix [deg, deg, m; std m, default 1 m];
//! - `baro t h`: a barometric height [m] (a bias state is estimated).
//!
//! Aids may arrive up to 0.5 s after their time (the session's reorder window); later
//! ones are reported on standard error. Output: `t lat lon h vn ve vd roll pitch yaw
//! σN σE σD` once a second on standard output.

use nalgebra::Vector3;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler::session::{Aid, Epoch, Event, FilterConfig, Session, SessionConfig, Start};
use schuler::sim::sensor_spec::{ImuSpec, Preset};
use std::io::{BufRead, Write};

/// What one input line holds.
enum Input {
    Imu(ImuSample),
    Aid(Aid),
}

/// Parse one line; `Ok(None)` for blank and comment lines.
fn parse(line: &str, last_imu_t: Option<f64>) -> Result<Option<Input>, String> {
    let mut words = line.split_whitespace();
    let Some(kind) = words.next().filter(|w| !w.starts_with('#')) else {
        return Ok(None);
    };
    let x: Vec<f64> = words
        .map(|w| w.parse::<f64>().map_err(|_| format!("not a number: {w:?}")))
        .collect::<Result<_, _>>()?;
    let deg = f64::to_radians;
    match (kind, x.as_slice()) {
        ("imu", [t, g @ ..]) if g.len() == 6 => Ok(Some(Input::Imu(ImuSample {
            t: *t,
            // The first sample carries the start; its interval is taken as 5 ms.
            dt: last_imu_t.map_or(0.005, |t0| t - t0),
            dtheta: Vector3::new(g[0], g[1], g[2]),
            dvel: Vector3::new(g[3], g[4], g[5]),
        }))),
        ("gnss", [t, lat, lon, h, std @ ..]) if std.is_empty() || std.len() == 3 => {
            let pos_std = if std.is_empty() {
                Vector3::repeat(1.0)
            } else {
                Vector3::from_column_slice(std)
            };
            Ok(Some(Input::Aid(Aid::Gnss(GnssFix {
                t: *t,
                pos: Geodetic::new(deg(*lat), deg(*lon), *h),
                pos_std,
                vel: None,
            }))))
        }
        ("baro", [t, h]) => Ok(Some(Input::Aid(Aid::Baro { t: *t, h: *h }))),
        _ => Err(format!(
            "expected `imu t 6 increments`, `gnss t lat lon h [3 std]` or `baro t h`, got {} numbers after {kind:?}",
            x.len()
        )),
    }
}

/// One epoch as a line.
fn print(out: &mut impl Write, e: &Epoch) -> std::io::Result<()> {
    let s = e.state.normalized();
    let a: Euler = s.euler();
    let sd = e.filter.map_or(Vector3::zeros(), |f| f.nav_std[0]);
    writeln!(
        out,
        "{:.3} {:.9} {:.9} {:.3} {:.3} {:.3} {:.3} {:.4} {:.4} {:.4} {:.3} {:.3} {:.3}",
        s.t,
        s.pos.lat.to_degrees(),
        s.pos.lon.to_degrees(),
        s.pos.h,
        s.v_n.x,
        s.v_n.y,
        s.v_n.z,
        a.roll.to_degrees(),
        a.pitch.to_degrees(),
        a.heading_0_2pi().to_degrees(),
        sd.x,
        sd.y,
        sd.z
    )?;
    out.flush()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("arguments: LAT LON H ROLL PITCH YAW (numbers): {e}"))?;
    let [lat, lon, h, roll, pitch, yaw] = args[..] else {
        return Err("arguments: LAT LON H ROLL PITCH YAW".into());
    };
    let start = NavState::new(
        0.0,
        Geodetic::from_degrees(lat, lon, h),
        Vector3::zeros(),
        Euler::from_degrees(roll, pitch, yaw),
    );
    let noise = ImuNoise::from_model(&ImuSpec::of_preset(200.0, Preset::Tactical).model()?);
    let config = SessionConfig {
        output_rate: Some(1.0),
        reorder_window: 0.5,
        filter: Some(FilterConfig::new(IntegrationConfig {
            baro: Some((10.0, 0.0)),
            ..IntegrationConfig::new(noise)
        })),
        ..SessionConfig::default()
    };
    let mut session = Session::new(Wgs84, config, Start::at(start))?;
    let mut out = std::io::stdout().lock();
    let mut last_imu_t = None;
    for (n, line) in std::io::stdin().lock().lines().enumerate() {
        let line = line?;
        let pushed = match parse(&line, last_imu_t) {
            Ok(None) => Ok(()),
            Ok(Some(Input::Imu(s))) => {
                last_imu_t = Some(s.t);
                session.push_imu(s).map_err(|e| e.to_string())
            }
            Ok(Some(Input::Aid(a))) => session.push(a).map_err(|e| e.to_string()),
            Err(e) => Err(e),
        };
        pushed.map_err(|e| format!("stdin:{}: {e}", n + 1))?;
        for e in session.epochs() {
            print(&mut out, &e)?;
        }
        for e in session.events() {
            if let Event::Late { t, kind, .. } | Event::Ignored { t, kind, .. } = e {
                eprintln!("{kind} at t = {t}: not used ({e:?})");
            }
        }
    }
    let end = session.finish()?;
    for e in &end.epochs {
        print(&mut out, e)?;
    }
    let c = end.summary.counts;
    eprintln!(
        "{} samples, {} positions and {} heights used, {} refused, {} late",
        end.summary.samples, c.position, c.baro, c.rejected, end.summary.late
    );
    Ok(())
}
