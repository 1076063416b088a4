//! `schuler demo`: a first end-to-end run on data simulated in memory.
//!
//! Three cases, each written as a KF-GINS IMU log with its truth and then navigated by
//! the same reader, mechanization and writers as `schuler nav`:
//! 1. `stationary`: 10 min at rest at 45 N, exact increments at 200 Hz;
//! 2. `maneuvering`: 10 min of turns, climbs, pitch and roll at 200 Hz;
//! 3. `schuler`: the textbook sphere (a = 6371 km, g = 9.81 m/s^2) at rest with a
//!    1e-3 m/s^2 north accelerometer bias for 100 min at 10 Hz: the velocity error
//!    oscillates with the Schuler period 2 pi sqrt(a/g) = 84.4 min (SEEDS.md (20)).

use super::nav::{EarthChoice, NavSettings, navigate};
use crate::formats::{ImuReadOptions, ImuReader};
use crate::output::{NavWriter, write_imu_text, write_truth_text};
use anyhow::{Context, Result};
use nalgebra::Vector3;
use schuler::earth::{EarthModel, Geodetic, Sphere, Wgs84};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler::sim::analytic::{self, Maneuvering, Stationary, Trajectory};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `schuler demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Output directory.
    #[arg(long, default_value = "schuler-demo")]
    pub out: PathBuf,
}

/// One demo case's outcome, compared with its truth.
struct CaseResult {
    name: &'static str,
    samples: u64,
    duration_s: f64,
    horizontal_max_m: f64,
    vertical_max_m: f64,
    attitude_max_arcsec: f64,
    note: String,
}

/// The errors of navigated epochs against truth evaluated at the same times.
struct ErrorStats {
    horizontal_max_m: f64,
    vertical_max_m: f64,
    attitude_max_rad: f64,
}

fn compare<E: EarthModel, T: Trajectory>(
    earth: &E,
    traj: &T,
    nav_csv: &Path,
) -> Result<ErrorStats> {
    let text = std::fs::read_to_string(nav_csv)
        .with_context(|| format!("cannot read {}", nav_csv.display()))?;
    let mut stats = ErrorStats {
        horizontal_max_m: 0.0,
        vertical_max_m: 0.0,
        attitude_max_rad: 0.0,
    };
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<f64> = line
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("{}:{}: not a number", nav_csv.display(), i + 1))?;
        anyhow::ensure!(
            f.len() == 10,
            "{}:{}: expected 10 columns",
            nav_csv.display(),
            i + 1
        );
        let truth = analytic::state(earth, traj, f[0]);
        let r = earth.radii(truth.pos.lat);
        let dn = (f[1].to_radians() - truth.pos.lat) * (r.meridian + truth.pos.h);
        let dlon = (f[2].to_radians() - truth.pos.lon + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        let de = dlon * (r.prime_vertical + truth.pos.h) * truth.pos.lat.cos();
        let q = Euler::from_degrees(f[7], f[8], f[9]).to_quaternion();
        stats.horizontal_max_m = stats.horizontal_max_m.max(dn.hypot(de));
        stats.vertical_max_m = stats.vertical_max_m.max((f[3] - truth.pos.h).abs());
        stats.attitude_max_rad = stats.attitude_max_rad.max(q.angle_to(&truth.q_bn));
    }
    Ok(stats)
}

/// Simulate `n` samples at `dt`, write them and the truth, navigate, compare.
#[allow(clippy::too_many_arguments)]
fn run_case<E: EarthModel, T: Trajectory>(
    name: &'static str,
    dir: &Path,
    earth: E,
    earth_choice: EarthChoice,
    traj: &T,
    dt: f64,
    n: usize,
    corrupt: impl Fn(ImuSample) -> ImuSample,
) -> Result<(CaseResult, ErrorStats)> {
    let case_dir = dir.join(name);
    std::fs::create_dir_all(&case_dir)
        .with_context(|| format!("cannot create {}", case_dir.display()))?;
    let imu_path = case_dir.join("imu.txt");
    // Sample 0 ends at t = 0 and carries the initial state; samples 1..=n follow.
    let samples = analytic::samples(&earth, traj, -dt, dt, n + 1).map(&corrupt);
    write_imu_text(&imu_path, samples, 17)?;
    let truth_epochs = (0..=n)
        .step_by(10)
        .map(|k| analytic::state(&earth, traj, k as f64 * dt));
    write_truth_text(&case_dir.join("truth.nav"), truth_epochs)?;

    let init: NavState = analytic::state(&earth, traj, 0.0);
    let e = init.euler();
    let settings = NavSettings {
        imu: imu_path.clone(),
        read: ImuReadOptions::default(),
        init_pos: init.pos,
        init_vel: init.v_n,
        init_att: e,
        output_rate: Some(10.0),
        out: case_dir.clone(),
        earth: earth_choice,
        week: 0,
    };
    let mut reader = ImuReader::open(&imu_path, &settings.read)?;
    let writer = NavWriter::create(&case_dir, 0)?;
    let summary = navigate(earth, &settings, &mut reader, writer, |_| {})?;
    let stats = compare(&earth, traj, &case_dir.join("nav.csv"))?;
    Ok((
        CaseResult {
            name,
            samples: summary.samples,
            duration_s: summary.t_last - summary.t_first,
            horizontal_max_m: stats.horizontal_max_m,
            vertical_max_m: stats.vertical_max_m,
            attitude_max_arcsec: stats.attitude_max_rad.to_degrees() * 3600.0,
            note: String::new(),
        },
        stats,
    ))
}

/// Zero crossings of the north velocity in `nav.csv` [s].
fn north_velocity_crossings(nav_csv: &Path) -> Result<Vec<f64>> {
    let text = std::fs::read_to_string(nav_csv)
        .with_context(|| format!("cannot read {}", nav_csv.display()))?;
    let mut prev: Option<(f64, f64)> = None;
    let mut crossings = Vec::new();
    for line in text.lines().skip(1) {
        let mut it = line.split(',');
        let t: f64 = it.next().unwrap_or("").parse()?;
        let vn: f64 = it.nth(3).unwrap_or("").parse()?;
        if let Some((t0, v0)) = prev
            && v0 != 0.0
            && vn != 0.0
            && v0.signum() != vn.signum()
        {
            crossings.push(t0 + (t - t0) * v0 / (v0 - vn));
        }
        prev = Some((t, vn));
    }
    Ok(crossings)
}

/// `schuler demo`.
pub fn run(args: DemoArgs) -> Result<()> {
    let started = Instant::now();
    let dir = &args.out;
    let mut results = Vec::new();

    let stationary = Stationary {
        pos: Geodetic::from_degrees(45.0, 7.68, 245.0),
        attitude: Euler::from_degrees(1.0, -0.5, 30.0),
    };
    let (r, _) = run_case(
        "stationary",
        dir,
        Wgs84,
        EarthChoice::Wgs84,
        &stationary,
        0.005,
        120_000,
        |s| s,
    )?;
    results.push(r);

    let flight = Maneuvering::flight(Geodetic::from_degrees(45.0, 7.68, 500.0));
    let (r, _) = run_case(
        "maneuvering",
        dir,
        Wgs84,
        EarthChoice::Wgs84,
        &flight,
        0.005,
        120_000,
        |s| s,
    )?;
    results.push(r);

    let sphere = Sphere::textbook(false);
    let at_rest = Stationary {
        pos: Geodetic::from_degrees(0.0, 0.0, 0.0),
        attitude: Euler::default(),
    };
    let bias = Vector3::new(1e-3, 0.0, 0.0);
    let (mut r, _) = run_case(
        "schuler",
        dir,
        sphere,
        EarthChoice::SphereFixed,
        &at_rest,
        0.1,
        60_000,
        |s| ImuSample {
            dvel: s.dvel + bias * s.dt,
            ..s
        },
    )?;
    let crossings = north_velocity_crossings(&dir.join("schuler").join("nav.csv"))?;
    let expected_min = std::f64::consts::TAU / sphere.schuler_frequency() / 60.0;
    r.note = match crossings.as_slice() {
        [half, full, ..] => format!(
            "Schuler period from velocity zero crossings {:.2} min (2(t2 - t1)) / {:.2} min (t2); theory 2 pi sqrt(a/g) = {:.2} min",
            2.0 * (full - half) / 60.0,
            full / 60.0,
            expected_min
        ),
        _ => format!("fewer than two velocity zero crossings: {crossings:?}"),
    };
    results.push(r);

    println!("schuler demo: free-inertial navigation of exact simulated IMU data\n");
    println!(
        "{:<12} {:>9} {:>10} {:>14} {:>13} {:>15}",
        "case", "samples", "duration", "horiz max [m]", "vert max [m]", "att max [\"]"
    );
    for r in &results {
        println!(
            "{:<12} {:>9} {:>8.0} s {:>14.3e} {:>13.3e} {:>15.3e}",
            r.name,
            r.samples,
            r.duration_s,
            r.horizontal_max_m,
            r.vertical_max_m,
            r.attitude_max_arcsec
        );
    }
    println!(
        "\nschuler (1e-3 m/s^2 accelerometer bias on the textbook sphere): the position error is"
    );
    println!(
        "df/w0^2 (1 - cos w0 t), up to 2 x 650 m; {}",
        results[2].note
    );
    println!(
        "\nresults in {} (imu.txt, truth.nav, nav.txt, nav.csv per case); {:.1} s",
        dir.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
