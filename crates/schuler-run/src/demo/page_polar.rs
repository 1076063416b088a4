//! The report's section "Across the pole" and the files behind it: the ground track
//! in a polar projection (`polar_track.csv`), the circular error of every mode
//! (`errors_polar_*.csv`, `nav_polar_*.csv`), the wander azimuth
//! (`polar_azimuth.csv`) and the crossing's own summary table (`polar_summary.csv`).

use super::errors::{self, height};
use super::modes::Track;
use super::page::{csv, find, m, plot_circular, svg, table_with_csv, write_mode};
use super::polar::Polar;
use super::{ModeRun, crossing::Crossing};
use anyhow::Result;
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Wgs84};
use schuler::nav::NavState;
use schuler_report::html::Report;
use schuler_report::plot::{LineStyle, Plot};
use std::path::Path;

/// Columns of `polar_summary.csv` and the section's table.
pub const POLAR_SUMMARY_HEADER: [&str; 9] = [
    "mode",
    "dS at outage start [m]",
    "dS over the pole [m]",
    "dS at outage end [m]",
    "dS at end [m]",
    "max dS [m]",
    "max |dh| [m]",
    "run time [s]",
    "data",
];

/// One row of the crossing's summary (the same strings go to `polar_summary.csv`).
fn summary_row(run: &ModeRun, c: &Crossing) -> Vec<String> {
    let e = &run.errors;
    let at = |t: f64| errors::at(e, t).map_or("-".to_string(), |x| m(x.horizontal()));
    let dh = e.iter().map(|x| height(x).abs()).fold(0.0, f64::max);
    vec![
        run.label.to_string(),
        at(c.outage.0),
        at(c.t_pole()),
        at(c.outage.1),
        e.last().map_or("-".to_string(), |x| m(x.horizontal())),
        m(errors::max_circular(e, c.t0, c.end())),
        m(dh),
        format!("{:.2}", run.track.seconds),
        format!("errors_{}.csv", run.key),
    ]
}

/// ECEF position [m] of a state (valid for a NED state carried past the pole, whose
/// latitude exceeds 90 deg: the geodetic formulas are continuous there).
fn ecef(s: &NavState) -> Vector3<f64> {
    Wgs84.geodetic_to_ecef(&s.pos)
}

/// Closest approach of `track`'s epochs to the polar axis [m]: the shortest distance
/// from the axis to the straight segments between consecutive epochs in the
/// equatorial plane (the path between epochs 1 s apart is straight to its curvature,
/// metres over 70 m).
fn closest_approach(track: &Track) -> f64 {
    let xy: Vec<nalgebra::Vector2<f64>> =
        track.epochs.iter().map(|e| ecef(&e.state).xy()).collect();
    xy.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let f = (-w[0].dot(&d) / d.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (w[0] + d * f).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Polar projection [km]: ECEF x (towards 0 E) and y (towards 90 E).
fn polar_xy(s: &NavState) -> (f64, f64) {
    let r = ecef(s);
    (r.x / 1e3, r.y / 1e3)
}

/// `x` [rad] as a continuous series in degrees (steps of more than 180 deg taken
/// the short way).
fn unwrapped_deg(x: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for v in x {
        let d = v.to_degrees();
        let next = match out.last() {
            Some(&prev) => prev + (d - prev + 180.0).rem_euclid(360.0) - 180.0,
            None => d,
        };
        out.push(next);
    }
    out
}

/// Index of the epoch of `track` at `t` (nearest whole second).
fn state_index(track: &Track, t: f64) -> Option<usize> {
    let t0 = track.epochs.first()?.state.t;
    let k = (t - t0).round().max(0.0) as usize;
    (k < track.epochs.len()).then_some(k)
}

/// The state of `track` at the time `t` of a truth epoch, if it has one then.
fn state_at(track: &Track, t: f64) -> Option<&NavState> {
    let e = &track.epochs[state_index(track, t)?];
    ((e.state.t - t).abs() < 1e-6).then_some(&e.state)
}

/// The ground tracks: `polar_track.csv` and the map.
fn ground_track(dir: &Path, p: &Polar, shown: &[&ModeRun]) -> Result<Plot> {
    let truth: Vec<(f64, f64)> = p.rec.truth.iter().map(|e| polar_xy(&e.state)).collect();
    let mut header = "t_s,truth_x_km,truth_y_km".to_string();
    for r in shown {
        header.push_str(&format!(",{0}_x_km,{0}_y_km", r.key));
    }
    let rows = p.rec.truth.iter().zip(&truth).map(|(e, (x, y))| {
        let mut row = format!("{:.0},{x:.4},{y:.4}", e.state.t);
        for r in shown {
            match state_at(&r.track, e.state.t).map(polar_xy) {
                Some((x, y)) => row.push_str(&format!(",{x:.4},{y:.4}")),
                None => row.push_str(",,"),
            }
        }
        row
    });
    csv(dir, "polar_track.csv", &header, rows)?;
    let (x, y): (Vec<f64>, Vec<f64>) = truth.into_iter().unzip();
    let mut map = Plot::new(
        "Ground track over the North Pole (polar projection)",
        "x towards 0 E [km]",
        "y towards 90 E [km]",
    )
    .line("truth", &x, &y, LineStyle::Solid);
    for (r, style) in shown.iter().zip([LineStyle::Dashed, LineStyle::Dotted]) {
        let (x, y): (Vec<f64>, Vec<f64>) =
            r.track.epochs.iter().map(|e| polar_xy(&e.state)).unzip();
        map = map.line(r.label, &x, &y, style);
    }
    svg(dir, "polar_track.svg", &map)?;
    Ok(map)
}

/// The wander azimuth of the wander runs, the true heading, and the heading in the
/// wander frame: `polar_azimuth.csv` and its plot.
fn azimuth(dir: &Path, p: &Polar, inertial: &ModeRun, aided: &ModeRun) -> Result<Plot> {
    let t: Vec<f64> = inertial.track.epochs.iter().map(|e| e.state.t).collect();
    let alpha = |r: &ModeRun| {
        unwrapped_deg(
            r.track
                .epochs
                .iter()
                .map(|e| e.wander_azimuth.unwrap_or(f64::NAN)),
        )
    };
    let (a_free, a_aided) = (alpha(inertial), alpha(aided));
    let heading = unwrapped_deg(t.iter().map(|&t| p.rec.truth_at(t).state.euler().yaw));
    let in_wander = unwrapped_deg(
        inertial
            .track
            .epochs
            .iter()
            .map(|e| e.state.euler().yaw - e.wander_azimuth.unwrap_or(f64::NAN)),
    );
    csv(
        dir,
        "polar_azimuth.csv",
        "t_s,alpha_inertial_deg,alpha_aided_deg,true_heading_deg,heading_in_wander_frame_deg",
        (0..t.len()).map(|k| {
            let get = |v: &[f64]| v.get(k).map_or(String::new(), |x| format!("{x:.4}"));
            format!(
                "{:.0},{},{},{},{}",
                t[k],
                get(&a_free),
                get(&a_aided),
                get(&heading),
                get(&in_wander)
            )
        }),
    )?;
    let plot = Plot::new("Wander azimuth across the pole", "t [s]", "angle [deg]")
        .line("wander azimuth, inertial", &t, &a_free, LineStyle::Solid)
        .line(
            "wander azimuth, inertial-satellite",
            &t,
            &a_aided,
            LineStyle::Dashed,
        )
        .line("true heading (from north)", &t, &heading, LineStyle::Dotted)
        .line(
            "heading in the wander frame, inertial",
            &t,
            &in_wander,
            LineStyle::Solid,
        );
    svg(dir, "polar_azimuth.svg", &plot)?;
    Ok(plot)
}

/// Peak cross-track speed of the crossing's weave [m/s]: 2π × amplitude / period.
fn weave_speed(c: &Crossing) -> f64 {
    std::f64::consts::TAU * c.weave.0 / c.weave.1
}

/// The section's opening paragraph: the flight, its simulation and the hand-over.
fn introduction(p: &Polar) -> String {
    let c = &p.crossing;
    let lat0 = p.rec.truth[0].state.pos.lat.to_degrees();
    format!(
        "A second, short flight: the sortie's helicopter with the same IMU, GNSS and \
         barometer (examples/polar_flight.toml, at {:.0} Hz) flies {:.0} s at {:.0} m/s and \
         300 m from {lat0:.2} N on 25 E straight over the North Pole (at t = {:.0} s) to \
         {lat0:.2} N on 155 W, weaving {:.0} m either side every {:.0} s, so it crosses the \
         pole {:.1} deg off the meridian. The scripted simulator stops at 89.9 deg (its \
         latitude and longitude rates are singular at the pole), so this flight is written \
         in ECEF (schuler::sim::analytic::Trajectory) and the IMU increments come from its \
         exact rates; the GNSS velocity is resolved at the receiver's own reported position, \
         as a receiver does. Navigation starts in flight from a hand-over: the truth with \
         errors of {:.1} m, {:.2} m/s, {:.1} arcmin level and {:.1} arcmin heading, the \
         sensor biases not known. GNSS is lost from {:.0} s to {:.0} s, around the pole.",
        p.rec.rate,
        c.duration,
        c.speed,
        c.t_pole(),
        c.weave.0,
        c.weave.1,
        weave_speed(c).atan2(c.speed).to_degrees(),
        c.handover.pos_n.norm(),
        c.handover.v_n.norm(),
        c.handover.psi.xy().norm().to_degrees() * 60.0,
        c.handover.psi.z.abs().to_degrees() * 60.0,
        c.outage.0,
        c.outage.1,
    )
}

/// How the wander-azimuth mechanization navigates the crossing and how its errors are
/// measured.
const WANDER_MECHANIZATION: &str = "The all-latitude wander-azimuth mechanization (the \
     seed's: position as the wander-to-Earth quaternion, the navigation frame's vertical \
     rate relative to the Earth held at zero, so nothing depends on the direction of \
     north) navigates it in the inertial mode with the baro loop and in the \
     inertial-satellite mode, the filter's errors resolved in the wander frame. Errors, as \
     everywhere in schuler, are differences in ECEF resolved along the truth's north and \
     east: latitude and longitude differences (R dlat, R cos(lat) dlon) would fail here, \
     because within tens of metres of the pole a metre of error spans degrees of \
     longitude (two points 30 m from the pole on opposite meridians are 60 m apart, not \
     94 m), and each state's velocity and heading are in its own north.";

/// The NED mechanization on the crossing's samples against the wander one: how close
/// its track passes the pole, how far its latitude goes, how fast its longitude turns,
/// and how far apart the two positions come.
fn ned_contrast(p: &Polar, wander: &ModeRun, ned: &ModeRun) -> String {
    let apart = wander
        .track
        .epochs
        .iter()
        .zip(&ned.track.epochs)
        .map(|(w, n)| (ecef(&w.state) - ecef(&n.state)).norm())
        .fold(0.0, f64::max);
    let max_lat = ned
        .track
        .epochs
        .iter()
        .map(|e| e.state.pos.lat)
        .fold(f64::NEG_INFINITY, f64::max);
    let closest = closest_approach(&ned.track);
    let ground_speed = p.crossing.speed.hypot(weave_speed(&p.crossing));
    format!(
        "The NED mechanization on the same samples (inertial mode): its own track passes {:.1} m \
         from the pole (between its 1-s epochs; its navigation error keeps it off the exact \
         point), its latitude {} 90 deg (largest {:.6} deg), and its longitude swings through \
         half a turn at up to v_E / ((R_N + h) cos lat), about V / d = {:.1} rad/s, which its \
         latitude-longitude step integrates in turns of {:.1} mrad per sample. Read through \
         ECEF, its position differs from the wander mechanization's by up to {} m over the \
         flight. NED is singular at the pole itself (cos lat = 0 divides the longitude and \
         transport rates), and the closer its own track passes, and the lower the sample \
         rate, the more it loses (schuler's wander_polar tests: 200 m within 30 s of a pass \
         6.4 m from the pole at 250 m/s and 200 Hz). The wander frame has no such rate: its \
         azimuth takes the half turn instead.",
        closest,
        if max_lat > std::f64::consts::FRAC_PI_2 {
            "runs beyond"
        } else {
            "stays below"
        },
        max_lat.to_degrees(),
        ground_speed / closest,
        ground_speed / p.rec.rate / closest * 1e3,
        m(apart),
    )
}

/// The wander azimuth's half turn at the pole, read from the inertial run `wander` 10 s
/// before and after it (alpha' = lon' sin(lat)).
fn azimuth_text(c: &Crossing, wander: &ModeRun) -> String {
    let alpha_at = |t: f64| {
        state_index(&wander.track, t)
            .and_then(|k| wander.track.epochs[k].wander_azimuth)
            .map_or(f64::NAN, f64::to_degrees)
    };
    format!(
        "The wander azimuth (the wander frame's x axis east of north) starts at 0 and turns \
         only as the meridians converge under the helicopter, alpha' = lon' sin(lat): slowly \
         while it weaves, then by half a turn as it crosses the pole ({:.1} deg 10 s before, \
         {:.1} deg 10 s after), exactly as north itself flips (the true heading). The \
         heading in the wander frame, yaw - alpha, is smooth throughout: nothing in the \
         mechanization sees the pole.",
        alpha_at(c.t_pole() - 10.0),
        alpha_at(c.t_pole() + 10.0),
    )
}

/// Write the crossing's files and its section into `report`; returns the summary
/// rows.
pub fn section(dir: &Path, report: &mut Report, p: &Polar) -> Result<Vec<Vec<String>>> {
    for r in &p.runs {
        write_mode(dir, r)?;
    }
    let c = &p.crossing;
    let inertial = find(&p.runs, "polar_inertial")?;
    let forward = find(&p.runs, "polar_aided")?;
    let smoothed = find(&p.runs, "polar_smoothed")?;
    let ned = find(&p.runs, "polar_ned")?;

    let sec = report.section("polar", "Across the pole");
    sec.paragraph(&introduction(p));
    sec.paragraph(WANDER_MECHANIZATION);
    let map = ground_track(dir, p, &[inertial, ned])?;
    sec.plot_with_files(&map, &["polar_track.svg", "polar_track.csv"]);

    let p_free = plot_circular(
        "Across the pole, inertial mode: circular error dS",
        &[inertial, ned],
        &[c.outage],
    );
    svg(dir, "polar_inertial_circular.svg", &p_free)?;
    let p_aided = plot_circular(
        "Across the pole, inertial-satellite mode: circular error dS",
        &[forward, smoothed],
        &[c.outage],
    );
    svg(dir, "polar_aided_circular.svg", &p_aided)?;
    sec.paragraph(&ned_contrast(p, inertial, ned));
    sec.plot_with_files(
        &p_free,
        &[
            "polar_inertial_circular.svg",
            "errors_polar_inertial.csv",
            "errors_polar_ned.csv",
        ],
    );
    sec.plot_with_files(
        &p_aided,
        &[
            "polar_aided_circular.svg",
            "errors_polar_aided.csv",
            "errors_polar_smoothed.csv",
        ],
    );

    let az = azimuth(dir, p, inertial, forward)?;
    sec.paragraph(&azimuth_text(c, inertial));
    sec.plot_with_files(&az, &["polar_azimuth.svg", "polar_azimuth.csv"]);

    let rows: Vec<Vec<String>> = p.runs.iter().map(|r| summary_row(r, c)).collect();
    let table = table_with_csv(dir, "polar_summary.csv", &POLAR_SUMMARY_HEADER, &rows)?;
    sec.table(table.caption("Errors across the pole (polar_summary.csv)"));
    sec.paragraph(&format!(
        "Simulation of the crossing {:.2} s; the modes ran in parallel.",
        p.simulate_s
    ));
    Ok(rows)
}
