//! `schuler nav --gnss ...`: INS/GNSS integration with the error-state filter
//! ([`schuler::filter::Integrator`]) on the NED mechanization. Besides `nav.txt` and
//! `nav.csv` it writes, at the output rate, `std.txt` (standard deviations) and
//! `imu_err.txt` (estimated sensor errors) in KF-GINS's column layouts, and at the end
//! `rejected.csv` (every measurement the gate refused or that fell outside the IMU
//! data, with time and reason) and `innovations.csv` (every measurement tested, with
//! its innovation, predicted standard deviations and NIS; [`super::aided_record`]).
//! Vehicle aiding (ZUPT, NHC, odometer, dual-antenna heading) is in [`super::vehicle`].

use super::aided_record::RunRecorder;
use super::aided_report::{ReportData, ReportSettings, RunFacts};
use super::nav::{Decimator, MechanizationKind, NavSettings, NavSummary};
use crate::output::{NavEpoch, NavWriter, push_fixed};
use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use schuler::earth::EarthModel;
use schuler::filter::integration::{Counts, SkipReason};
use schuler::filter::{GnssFix, IntegrationConfig, Integrator, Layout};
use schuler::imu::ImuSample;
use schuler::nav::{ErrorFrame, LocalLevel, Mechanization, NavState, Wander};
use schuler::units::{DEG_PER_H, MGAL, PPM};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// File names of an aided run's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputNames {
    /// Navigation result (KF-GINS text).
    pub nav: &'static str,
    /// Standard deviations.
    pub std: &'static str,
    /// Sensor errors.
    pub imu_err: &'static str,
}

impl OutputNames {
    /// schuler's own names.
    pub const SCHULER: OutputNames = OutputNames {
        nav: "nav.txt",
        std: "std.txt",
        imu_err: "imu_err.txt",
    };
    /// KF-GINS's names.
    pub const KF_GINS: OutputNames = OutputNames {
        nav: "KF_GINS_Navresult.nav",
        std: "KF_GINS_STD.txt",
        imu_err: "KF_GINS_IMU_ERR.txt",
    };
}

/// What aiding a run has.
#[derive(Debug, Clone)]
pub struct Aiding {
    /// GNSS fixes in time order.
    pub fixes: Vec<GnssFix>,
    /// The filter's settings.
    pub config: IntegrationConfig,
    /// Write the smoothed trajectory too.
    pub smooth: bool,
    /// Output file names.
    pub names: OutputNames,
    /// Sensor errors known at the start (removed from the first sample on).
    pub initial_errors: schuler::filter::SensorEstimates,
    /// Test outages (GNSS removed inside), with the truth to report against.
    pub outage_test: Option<OutageTest>,
    /// Barometer readings `(t, h)` and their noise standard deviation [m].
    pub baro: Option<(Vec<(f64, f64)>, f64)>,
    /// The report: whether to write `report.html`, and the truths it compares with.
    pub report: ReportSettings,
    /// Vehicle aiding.
    pub vehicle: super::vehicle::VehicleAiding,
}

/// The outage test of `--outage-test`.
#[derive(Debug, Clone, PartialEq)]
pub struct OutageTest {
    /// The outages [s].
    pub windows: Vec<(f64, f64)>,
    /// Truth to report the errors against.
    pub truth: Option<PathBuf>,
}

/// What an aided run did, beyond [`NavSummary`].
#[derive(Debug, Clone, PartialEq)]
pub struct AidedSummary {
    /// The navigation summary.
    pub nav: NavSummary,
    /// Filter counters.
    pub counts: Counts,
    /// Mean normalized innovation squared per dimension of the accepted updates.
    pub mean_nis_per_dof: f64,
    /// The consistency summary (and the report's path) to print.
    pub report_text: String,
}

/// Text writer for `std.txt` and `imu_err.txt`.
struct Table {
    w: BufWriter<File>,
    path: PathBuf,
    line: Vec<u8>,
}

impl Table {
    fn create(dir: &Path, name: &str) -> Result<Self> {
        let path = dir.join(name);
        let f = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(Self {
            w: BufWriter::with_capacity(1 << 16, f),
            path,
            line: Vec::with_capacity(512),
        })
    }

    fn row(&mut self, t: f64, values: &[f64]) -> Result<()> {
        self.line.clear();
        push_table_row(&mut self.line, t, values);
        self.w
            .write_all(&self.line)
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    fn finish(mut self) -> Result<()> {
        self.w
            .flush()
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

use schuler::filter::kalman::std3;

/// A mechanization the aided navigation can run on.
pub trait AidedMechanization<E: EarthModel>: ErrorFrame + Sized {
    /// Which one it is.
    const KIND: MechanizationKind;
    /// Start at `init`.
    fn start(earth: E, init: NavState) -> Self;
    /// The epoch to write (NED state, ECEF position, wander azimuth).
    fn epoch(&self, earth: &E) -> NavEpoch;
}

impl<E: EarthModel> AidedMechanization<E> for LocalLevel<E> {
    const KIND: MechanizationKind = MechanizationKind::Ned;
    fn start(earth: E, init: NavState) -> Self {
        LocalLevel::new(earth, init)
    }
    fn epoch(&self, earth: &E) -> NavEpoch {
        let state = self.state();
        NavEpoch {
            state,
            r_e: earth.geodetic_to_ecef(&state.pos),
            wander_azimuth: 0.0,
        }
    }
}

impl<E: EarthModel> AidedMechanization<E> for Wander<E> {
    const KIND: MechanizationKind = MechanizationKind::Wander;
    fn start(earth: E, init: NavState) -> Self {
        Wander::new(earth, init)
    }
    fn epoch(&self, _earth: &E) -> NavEpoch {
        let (state, wander_azimuth) = self.nav_state_and_azimuth();
        NavEpoch {
            state,
            r_e: self.ecef_position(),
            wander_azimuth,
        }
    }
}

fn write_epoch<E: EarthModel, M: AidedMechanization<E>>(
    integ: &Integrator<M, E>,
    earth: &E,
    nav: &mut NavWriter,
    std: &mut Table,
    err: &mut Table,
) -> Result<()> {
    let state = integ.state();
    nav.write_epoch(&integ.mechanization().epoch(earth))?;
    let [sp, sv, sa] = integ.nav_std();
    let p = integ.covariance();
    let l = integ.layout();
    let scale = |o: Option<usize>| o.map_or(Vector3::zeros(), |o| std3(p, o));
    let mut row = Vec::with_capacity(21);
    row.extend_from_slice(sp.as_slice());
    row.extend_from_slice(sv.as_slice());
    row.extend(sa.iter().map(|x| x.to_degrees()));
    row.extend(std3(p, Layout::GYRO_BIAS).iter().map(|x| x / DEG_PER_H));
    row.extend(std3(p, Layout::ACCEL_BIAS).iter().map(|x| x / MGAL));
    row.extend(scale(l.gyro_scale).iter().map(|x| x / PPM));
    row.extend(scale(l.accel_scale).iter().map(|x| x / PPM));
    std.row(state.t, &row)?;
    let e = integ.estimates();
    err.row(state.t, &imu_err_row(&e))
}

/// A line of `std.txt` or `imu_err.txt`: time to 1 µs, then the values to 9 decimals,
/// space-separated.
pub(crate) fn push_table_row(line: &mut Vec<u8>, t: f64, values: &[f64]) {
    push_fixed(line, t, 6);
    for v in values {
        line.push(b' ');
        push_fixed(line, *v, 9);
    }
    line.push(b'\n');
}

/// The KF-GINS IMU_ERR columns after time: gyro bias [deg/h], accelerometer bias
/// [mGal], gyro and accelerometer scale factors [ppm].
pub(crate) fn imu_err_row(e: &schuler::filter::SensorEstimates) -> Vec<f64> {
    let mut row = Vec::with_capacity(12);
    row.extend(e.gyro_bias.iter().map(|x| x / DEG_PER_H));
    row.extend(e.accel_bias.iter().map(|x| x / MGAL));
    row.extend(e.gyro_scale.iter().map(|x| x / PPM));
    row.extend(e.accel_scale.iter().map(|x| x / PPM));
    row
}

/// The smoothed trajectory: `nav.txt`, `nav.csv`, `std.txt`, `imu_err.txt` in `dir`.
fn write_smoothed<E: EarthModel, M: ErrorFrame>(
    earth: &E,
    dir: &Path,
    week: u32,
    integ: &Integrator<M, E>,
) -> Result<()> {
    let mut nav = NavWriter::create_extended(dir, week, earth)?;
    let mut std = Table::create(dir, "std.txt")?;
    let mut err = Table::create(dir, "imu_err.txt")?;
    for s in integ.smoothed() {
        nav.write_epoch(&NavEpoch {
            state: s.state,
            r_e: earth.geodetic_to_ecef(&s.state.pos),
            wander_azimuth: 0.0,
        })?;
        let mut row: Vec<f64> = s.std[0].iter().chain(s.std[1].iter()).copied().collect();
        row.extend(s.std[2].iter().map(|x| x.to_degrees()));
        std.row(s.state.t, &row)?;
        err.row(s.state.t, &imu_err_row(&s.estimates))?;
    }
    nav.finish()?;
    std.finish()?;
    err.finish()
}

fn write_rejections<E: EarthModel, M: ErrorFrame>(
    dir: &Path,
    integ: &Integrator<M, E>,
) -> Result<()> {
    let path = dir.join("rejected.csv");
    let mut s = String::from("t,measurement,reason,nis,threshold\n");
    let mut rows: Vec<(f64, String)> = integ
        .rejected
        .iter()
        .map(|r| {
            (
                r.t,
                format!(
                    "{},{},chi-square gate,{},{}\n",
                    r.t, r.kind, r.rejection.nis, r.rejection.threshold
                ),
            )
        })
        .collect();
    rows.extend(integ.skipped.iter().map(|k| {
        let why = match k.reason {
            SkipReason::BeforeImu => "before the IMU data",
            SkipReason::AfterImu => "after the IMU data",
        };
        (k.t, format!("{},{},{why},,\n", k.t, k.kind))
    }));
    rows.extend(integ.gate_resets.iter().map(|t| {
        (*t, format!("{t},gnss_position,accepted without the gate after consecutive refusals (filter reset),,\n"))
    }));
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, r) in rows {
        s.push_str(&r);
    }
    std::fs::write(&path, s).with_context(|| format!("cannot write {}", path.display()))
}

/// Run the integrated navigation over `samples` (the first carries the initial state)
/// with the NED mechanization, writing into `settings.out`. On a read error everything
/// computed so far is written before the error is returned.
pub fn navigate_aided<E: EarthModel, I>(
    earth: E,
    settings: &NavSettings,
    aiding: &Aiding,
    samples: I,
    writer: NavWriter,
    on_sample: impl FnMut(u64),
) -> Result<AidedSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    navigate_aided_on::<LocalLevel<E>, E, I>(earth, settings, aiding, samples, writer, on_sample)
}

/// As [`navigate_aided`] on the mechanization `M` (NED or the all-latitude wander
/// mechanization, with which the filter works through the poles).
pub fn navigate_aided_on<M: AidedMechanization<E>, E: EarthModel, I>(
    earth: E,
    settings: &NavSettings,
    aiding: &Aiding,
    mut samples: I,
    mut writer: NavWriter,
    mut on_sample: impl FnMut(u64),
) -> Result<AidedSummary>
where
    I: Iterator<Item = Result<ImuSample, crate::formats::InputError>>,
{
    let (first, init) = super::nav::first_sample(settings, &mut samples)?;
    let mut integ = aiding.vehicle.configure(
        Integrator::new(M::start(earth, init), earth, aiding.config)
            .with_estimates(aiding.initial_errors),
    );
    if aiding.smooth {
        integ = integ.with_smoother();
    }
    integ.prime(&first);
    let mut std = Table::create(&settings.out, aiding.names.std)?;
    let mut err = Table::create(&settings.out, aiding.names.imu_err)?;
    let mut recorder = RunRecorder::create(&settings.out, aiding.report.truth_rows())?;
    let mut fixes = aiding.fixes.iter().copied().peekable();
    let mut decimator = Decimator::new(settings.output_rate);
    decimator.take(first.t, first.dt);
    integ.record_output();
    write_epoch(&integ, &earth, &mut writer, &mut std, &mut err)?;
    recorder.after_sample(&mut integ, first.t, first.dt)?;
    let mut n = 0u64;
    let mut last_t = first.t;
    let mut failure = None;
    let mut next_baro = 0usize;
    let mut vehicle = aiding.vehicle.start();
    for s in samples.by_ref() {
        let s = match s {
            Ok(s) => s,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        integ.step_with_fixes(&s, &mut fixes);
        if let Some((readings, std)) = &aiding.baro {
            // Readings up to half a sample past this one's end apply here.
            while next_baro < readings.len() && readings[next_baro].0 <= s.t + 0.5 * s.dt {
                let (t, h) = readings[next_baro];
                if t > s.t - 0.5 * s.dt {
                    integ.update_baro(t, h, *std);
                }
                next_baro += 1;
            }
        }
        vehicle.after_sample(&mut integ, &s);
        recorder.after_sample(&mut integ, s.t, s.dt)?;
        n += 1;
        last_t = s.t;
        if decimator.take(s.t, s.dt) {
            integ.record_output();
            write_epoch(&integ, &earth, &mut writer, &mut std, &mut err)?;
        }
        if n.is_multiple_of(65_536) {
            on_sample(n);
        }
    }
    for f in fixes {
        integ.skip(f.t, SkipReason::AfterImu);
    }
    vehicle.finish(&mut integ);
    let epochs = writer.finish()?;
    std.finish()?;
    err.finish()?;
    recorder.innovations.finish()?;
    write_rejections(&settings.out, &integ)?;
    if aiding.smooth {
        write_smoothed(
            &earth,
            &settings.out.join("smoothed"),
            settings.week,
            &integ,
        )?;
    }
    if let Some(e) = failure {
        return Err(anyhow::Error::new(e).context(format!(
            "stopped after {n} samples; {epochs} epochs up to t = {last_t} were written to {}",
            settings.out.display()
        )));
    }
    let (sum, dof) = recorder
        .innovations
        .rows
        .iter()
        .filter(|i| i.accepted)
        .fold((0.0, 0usize), |(s, d), i| (s + i.nis, d + i.dof));
    let report_text = super::aided_report::write(
        &settings.out,
        aiding.report.html,
        &ReportData {
            facts: RunFacts {
                imu: &settings.imu,
                nav_file: &settings.out.join(aiding.names.nav),
                mechanization: M::KIND,
                layout: integ.layout(),
                samples: n,
                t_first: first.t,
                t_last: last_t,
                counts: integ.counts,
                gate_resets: integ.gate_resets.len(),
                fixes: &aiding.fixes,
            },
            recorder: &recorder,
            settings: &aiding.report,
        },
    )?;
    Ok(AidedSummary {
        nav: NavSummary {
            samples: n,
            epochs,
            t_first: first.t,
            t_last: last_t,
            last: integ.state(),
            gaps: None,
            first_mechanization: M::KIND,
            handovers: Vec::new(),
        },
        counts: integ.counts,
        mean_nis_per_dof: if dof > 0 { sum / dof as f64 } else { f64::NAN },
        report_text,
    })
}

/// The aiding options of `schuler nav`, as written (flags, or a `[aiding]` table in
/// the TOML config).
#[derive(clap::Args, Debug, Default, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AidingOptions {
    /// GNSS position log: KF-GINS text (t lat lon h std_n std_e std_d [vn ve vd
    /// std_vn std_ve std_vd], whose velocities are then used) or CSV whose header names
    /// t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m (as `schuler simulate`'s gnss.csv;
    /// its velocity columns are used only through --gnss-vel, its outlier flag never).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub gnss: Option<PathBuf>,
    /// GNSS velocity log matched to the fixes by time: text t vn ve vd [std_vn std_ve
    /// std_vd] or CSV naming t,vn_mps,ve_mps,vd_mps[,std_vn_mps,...] (gnss.csv too); a
    /// position log given here is an error.
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub gnss_vel: Option<PathBuf>,
    /// Velocity standard deviation where the velocity log gives none (default 0.1 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    pub gnss_vel_std: Option<String>,
    /// Antenna position in body axes, front, right, down [m].
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub lever_arm: Option<super::nav::Triple>,
    /// Innovation gate: significance level of the chi-square test (default 1e-4; 0
    /// turns the gate off).
    #[arg(long, allow_hyphen_values = true, value_name = "ALPHA")]
    pub gate: Option<f64>,
    /// Estimate gyro and accelerometer scale factors (21 states).
    #[arg(long)]
    #[serde(default)]
    pub scale_factors: bool,
    /// Also write the Rauch–Tung–Striebel smoothed trajectory (forward-backward) at
    /// the output rate into `OUT/smoothed/` (the forward result stays in `OUT/`).
    #[arg(long)]
    #[serde(default)]
    pub smooth: bool,
    /// Angle random walk (e.g. `0.1 deg/sqrt(h)`; default from --imu-grade).
    #[arg(long, allow_hyphen_values = true, value_name = "ARW")]
    pub arw: Option<String>,
    /// Velocity random walk (e.g. `0.08 m/s/sqrt(h)`).
    #[arg(long, allow_hyphen_values = true, value_name = "VRW")]
    pub vrw: Option<String>,
    /// Gyro bias standard deviation (e.g. `2 deg/h`).
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    pub gyro_bias_std: Option<String>,
    /// Accelerometer bias standard deviation (e.g. `300 mGal`).
    #[arg(long, allow_hyphen_values = true, value_name = "ACCEL")]
    pub accel_bias_std: Option<String>,
    /// Gyro scale-factor standard deviation (e.g. `1000 ppm`; with --scale-factors).
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    pub gyro_scale_std: Option<String>,
    /// Accelerometer scale-factor standard deviation.
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    pub accel_scale_std: Option<String>,
    /// Bias instability (Gauss–Markov std, e.g. `0.2 deg/h` and `2e-4 m/s^2`) with
    /// --bias-corr-time: sets the bias random walk.
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    pub gyro_bias_instability: Option<String>,
    /// Accelerometer bias instability.
    #[arg(long, allow_hyphen_values = true, value_name = "ACCEL")]
    pub accel_bias_instability: Option<String>,
    /// Correlation time of the bias instability (default 1 h); given, the biases are
    /// modelled as first-order Gauss–Markov processes, otherwise as random walks.
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    pub bias_corr_time: Option<String>,
    /// Initial position standard deviation north, east, down [m] (default 1,1,1).
    #[arg(long, allow_hyphen_values = true, value_name = "N,E,D")]
    pub init_pos_std: Option<super::nav::Triple>,
    /// Initial velocity standard deviation [m/s] (default 0.1,0.1,0.1).
    #[arg(long, allow_hyphen_values = true, value_name = "N,E,D")]
    pub init_vel_std: Option<super::nav::Triple>,
    /// Initial attitude standard deviation roll, pitch, yaw [deg] (default 0.1,0.1,0.5).
    #[arg(long, allow_hyphen_values = true, value_name = "R,P,Y")]
    pub init_att_std: Option<super::nav::Triple>,
    /// Barometer log (`baro.csv` of `schuler simulate`: t,h_m; or `t h` rows): height
    /// aiding with a bias state.
    #[arg(long, value_name = "FILE")]
    pub baro: Option<PathBuf>,
    /// Barometer noise standard deviation (default 0.5 m).
    #[arg(long, allow_hyphen_values = true, value_name = "LENGTH")]
    pub baro_std: Option<String>,
    /// Prior standard deviation of the barometer bias (default 10 m).
    #[arg(long, allow_hyphen_values = true, value_name = "LENGTH")]
    pub baro_bias_std: Option<String>,
    /// Outage test: remove GNSS for LEN every PERIOD (e.g. `60s/180s`), the first
    /// outage starting at --outage-start (default: one PERIOD after the first fix);
    /// with --truth, report the errors at the end of and inside each outage.
    #[arg(long, allow_hyphen_values = true, value_name = "LEN/PERIOD")]
    pub outage_test: Option<String>,
    /// Start of the first test outage [s, the log's clock].
    #[arg(long, allow_hyphen_values = true, value_name = "SOW")]
    pub outage_start: Option<f64>,
    /// Truth (KF-GINS navigation text or schuler CSV): the report's position errors
    /// and NEES, and the outage test's errors.
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub truth: Option<PathBuf>,
    /// Truth of the sensor errors for the report, in imu_err.txt's layout (`t`, gyro
    /// bias [deg/h], accelerometer bias [mGal], optionally scale factors [ppm]).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub sensor_truth: Option<PathBuf>,
    /// Do not write report.html and report/ (innovations.csv and consistency.json are
    /// always written).
    #[arg(long)]
    #[serde(default)]
    pub no_report: bool,
    /// Longest covariance propagation step (default 1 s; the covariance is always
    /// propagated to each measurement's time).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    pub propagation_interval: Option<String>,
    /// Zero-velocity updates inside the rest intervals of FILE (`t0 t1` per line).
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "FILE",
        conflicts_with = "zupt_detect"
    )]
    pub zupt: Option<PathBuf>,
    /// Zero-velocity updates where the IMU data look at rest (the alignment's motion
    /// detector on a 1-s window, specific force against gravity, rate against the
    /// Earth's) and the navigation's speed is below --zupt-max-speed.
    #[arg(long)]
    #[serde(default)]
    pub zupt_detect: bool,
    /// Zero-velocity standard deviation (default 0.02 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    pub zupt_std: Option<String>,
    /// Time between zero-velocity updates at rest, and the detector's block
    /// (default 0.1 s; the detector's window is ten blocks).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    pub zupt_interval: Option<String>,
    /// --zupt-detect: no update while the navigation's speed exceeds this (an IMU
    /// cannot tell rest from constant velocity; default 0.5 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    pub zupt_max_speed: Option<String>,
    /// With each zero-velocity update, a zero-angular-rate update on the gyro biases
    /// (the body turns with the Earth only).
    #[arg(long)]
    #[serde(default)]
    pub zaru: bool,
    /// Standard deviation of the rate averaged over --zupt-interval (default: the angle
    /// random walk over that time, ARW/sqrt(interval)).
    #[arg(long, allow_hyphen_values = true, value_name = "RATE")]
    pub zaru_std: Option<String>,
    /// Non-holonomic constraint of a land vehicle: no lateral or vertical velocity of
    /// the vehicle frame at --vehicle-lever-arm.
    #[arg(long)]
    #[serde(default)]
    pub nhc: bool,
    /// NHC standard deviation (default 0.1 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    pub nhc_std: Option<String>,
    /// Time between NHC updates (default 0.1 s).
    #[arg(long, allow_hyphen_values = true, value_name = "TIME")]
    pub nhc_interval: Option<String>,
    /// Odometer log (`t speed` per line, forward speed in m/s at --vehicle-lever-arm).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub odometer: Option<PathBuf>,
    /// Odometer speed standard deviation (default 0.05 m/s).
    #[arg(long, allow_hyphen_values = true, value_name = "SPEED")]
    pub odometer_std: Option<String>,
    /// Estimate the odometer's scale factor with this prior standard deviation (e.g.
    /// `1 %`).
    #[arg(long, allow_hyphen_values = true, value_name = "RATIO")]
    pub odometer_scale_std: Option<String>,
    /// Mounting angles: the vehicle frame's roll, pitch, yaw relative to the IMU body
    /// [deg] (0,0,0 when the IMU's axes are the vehicle's front, right, down).
    #[arg(long, allow_hyphen_values = true, value_name = "R,P,Y")]
    pub mounting_angles: Option<super::nav::Triple>,
    /// The point the NHC and the odometer speak of (the rear axle's centre, the
    /// odometer wheel) in IMU body axes, front, right, down [m] (default 0,0,0).
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub vehicle_lever_arm: Option<super::nav::Triple>,
    /// Dual-antenna GNSS headings (`t heading std [pitch pitch_std]`, degrees).
    #[arg(long, allow_hyphen_values = true, value_name = "FILE")]
    pub dual_antenna: Option<PathBuf>,
    /// Azimuth of the antenna baseline (from the first antenna to the second) from
    /// the IMU's front axis towards its right [deg] (default 0).
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub dual_antenna_baseline_yaw: Option<f64>,
    /// Elevation of the baseline above the IMU's front-right plane [deg] (default 0).
    #[arg(long, allow_hyphen_values = true, value_name = "DEG")]
    pub dual_antenna_baseline_pitch: Option<f64>,
}

impl AidingOptions {
    /// `self` with missing fields taken from `other`.
    pub fn or(self, other: AidingOptions) -> AidingOptions {
        macro_rules! pick {
            ($($f:ident),*) => { AidingOptions { $($f: self.$f.or(other.$f),)* scale_factors: self.scale_factors || other.scale_factors, smooth: self.smooth || other.smooth, no_report: self.no_report || other.no_report, zupt_detect: self.zupt_detect || other.zupt_detect, zaru: self.zaru || other.zaru, nhc: self.nhc || other.nhc } };
        }
        pick!(
            gnss,
            gnss_vel,
            gnss_vel_std,
            lever_arm,
            gate,
            arw,
            vrw,
            gyro_bias_std,
            accel_bias_std,
            gyro_scale_std,
            accel_scale_std,
            gyro_bias_instability,
            accel_bias_instability,
            bias_corr_time,
            init_pos_std,
            init_vel_std,
            init_att_std,
            baro,
            baro_std,
            baro_bias_std,
            outage_test,
            outage_start,
            truth,
            sensor_truth,
            propagation_interval,
            zupt,
            zupt_std,
            zupt_interval,
            zupt_max_speed,
            zaru_std,
            nhc_std,
            nhc_interval,
            odometer,
            odometer_std,
            odometer_scale_std,
            mounting_angles,
            vehicle_lever_arm,
            dual_antenna,
            dual_antenna_baseline_yaw,
            dual_antenna_baseline_pitch
        )
    }

    /// Paths relative to `base` (a config file's folder).
    pub fn relative_to(mut self, base: &Path) -> Self {
        for p in [
            &mut self.gnss,
            &mut self.gnss_vel,
            &mut self.truth,
            &mut self.sensor_truth,
            &mut self.baro,
            &mut self.zupt,
            &mut self.odometer,
            &mut self.dual_antenna,
        ]
        .into_iter()
        .flatten()
        {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        }
        self
    }

    /// Whether any aiding source is given (GNSS, barometer or a vehicle aid).
    pub fn any(&self) -> bool {
        self.gnss.is_some()
            || self.baro.is_some()
            || self.zupt.is_some()
            || self.zupt_detect
            || self.nhc
            || self.odometer.is_some()
            || self.dual_antenna.is_some()
    }

    /// Load the aiding data and check every value; `None` without any aiding source
    /// ([`AidingOptions::any`]).
    pub fn resolve(&self, noise: schuler::filter::ImuNoise) -> Result<Option<Aiding>> {
        use schuler::units::{Dimension, parse_as_or_si};
        if self.gnss.is_none() && self.gnss_vel.is_some() {
            bail!("--gnss-vel needs --gnss (velocities are matched to position fixes)");
        }
        super::vehicle::check_dependencies(self)?;
        if !self.any() {
            return Ok(None);
        }
        let q = quantity;
        let mut fixes = match &self.gnss {
            Some(gnss) => crate::formats::gnss::read_gnss(gnss)?,
            None => Vec::new(),
        };
        if let Some(v) = &self.gnss_vel {
            let std = q("gnss-vel-std", &self.gnss_vel_std, Dimension::Velocity)?.unwrap_or(0.1);
            if std <= 0.0 {
                bail!("--gnss-vel-std must be positive");
            }
            let unmatched = crate::formats::gnss::merge_velocity(&mut fixes, v, std)?;
            if unmatched > 0 {
                eprintln!(
                    "warning: {}: {unmatched} velocity epochs have no position fix at the same time and are not used",
                    v.display()
                );
            }
        }
        let mut noise = noise;
        if let Some(x) = q("arw", &self.arw, Dimension::AngleRandomWalk)? {
            noise.arw = Vector3::repeat(x);
        }
        if let Some(x) = q("vrw", &self.vrw, Dimension::VelocityRandomWalk)? {
            noise.vrw = Vector3::repeat(x);
        }
        if let Some(x) = q("gyro-bias-std", &self.gyro_bias_std, Dimension::AngularRate)? {
            noise.gyro_bias = Vector3::repeat(x);
        }
        if let Some(x) = q(
            "accel-bias-std",
            &self.accel_bias_std,
            Dimension::Acceleration,
        )? {
            noise.accel_bias = Vector3::repeat(x);
        }
        if let Some(x) = q(
            "gyro-scale-std",
            &self.gyro_scale_std,
            Dimension::Dimensionless,
        )? {
            noise.gyro_scale = Vector3::repeat(x);
        }
        if let Some(x) = q(
            "accel-scale-std",
            &self.accel_scale_std,
            Dimension::Dimensionless,
        )? {
            noise.accel_scale = Vector3::repeat(x);
        }
        let tau_given = q("bias-corr-time", &self.bias_corr_time, Dimension::Time)?;
        let tau = tau_given.unwrap_or(3600.0);
        if tau <= 0.0 {
            bail!("--bias-corr-time must be positive");
        }
        if tau_given.is_some() {
            // A correlation time makes the biases Gauss–Markov (as KF-GINS models them).
            noise.gyro_bias_tau = tau;
            noise.accel_bias_tau = tau;
        }
        if let Some(x) = q(
            "gyro-bias-instability",
            &self.gyro_bias_instability,
            Dimension::AngularRate,
        )? {
            noise.gyro_bias_walk = Vector3::repeat(x * (2.0 / tau).sqrt());
        }
        if let Some(x) = q(
            "accel-bias-instability",
            &self.accel_bias_instability,
            Dimension::Acceleration,
        )? {
            noise.accel_bias_walk = Vector3::repeat(x * (2.0 / tau).sqrt());
        }
        let outage_test = match &self.outage_test {
            None => None,
            Some(text) => {
                let (len, period) = text.split_once('/').with_context(|| {
                    format!("--outage-test {text:?}: expected LEN/PERIOD, e.g. 60s/180s")
                })?;
                let t = |s: &str| -> Result<f64> {
                    parse_as_or_si(s.trim(), Dimension::Time)
                        .with_context(|| format!("--outage-test {text:?}"))
                };
                let (len, period) = (t(len)?, t(period)?);
                if !(len > 0.0 && period > len) {
                    bail!("--outage-test {text:?}: need 0 < LEN < PERIOD");
                }
                let (first, last) = (
                    fixes.first().map_or(0.0, |f| f.t),
                    fixes.last().map_or(0.0, |f| f.t),
                );
                let mut start = self.outage_start.unwrap_or(first + period);
                let mut windows = Vec::new();
                while start + len <= last {
                    windows.push((start, start + len));
                    start += period;
                }
                if windows.is_empty() {
                    bail!(
                        "--outage-test {text:?}: no whole outage fits between the first and last GNSS fix"
                    );
                }
                fixes.retain(|f| !windows.iter().any(|&(a, b)| f.t > a && f.t <= b));
                Some(OutageTest {
                    windows,
                    truth: self.truth.clone(),
                })
            }
        };
        let mut baro_cfg = None;
        let baro_readings = match &self.baro {
            None => None,
            Some(path) => {
                let readings = crate::formats::gnss::read_baro(path)?;
                let std = q("baro-std", &self.baro_std, Dimension::Length)?.unwrap_or(0.5);
                let bias =
                    q("baro-bias-std", &self.baro_bias_std, Dimension::Length)?.unwrap_or(10.0);
                if std <= 0.0 || bias <= 0.0 {
                    bail!("--baro-std and --baro-bias-std must be positive");
                }
                baro_cfg = Some((bias, 0.0));
                Some((readings, std))
            }
        };
        let gate = match self.gate {
            None => schuler::filter::Gate::Level(1e-4),
            Some(0.0) => schuler::filter::Gate::Off,
            Some(a) if a > 0.0 && a < 1.0 => schuler::filter::Gate::Level(a),
            Some(a) => bail!("--gate must be a significance level in [0, 1), got {a}"),
        };
        let triple = |flag: &str,
                      v: &Option<super::nav::Triple>,
                      default: [f64; 3]|
         -> Result<Vector3<f64>> {
            let t = v.map_or(default, |t| t.0);
            if t.iter().any(|x| *x <= 0.0) {
                bail!("--{flag} must be positive, got {t:?}");
            }
            Ok(Vector3::from(t))
        };
        let att = triple("init-att-std", &self.init_att_std, [0.1, 0.1, 0.5])?;
        let propagation_interval = q(
            "propagation-interval",
            &self.propagation_interval,
            Dimension::Time,
        )?
        .unwrap_or(1.0);
        if propagation_interval <= 0.0 {
            bail!("--propagation-interval must be positive");
        }
        let vehicle = super::vehicle::resolve(self, &noise)?;
        Ok(Some(Aiding {
            vehicle,
            smooth: self.smooth,
            names: OutputNames::SCHULER,
            initial_errors: Default::default(),
            outage_test,
            baro: baro_readings,
            report: ReportSettings {
                html: !self.no_report,
                truth: match &self.truth {
                    Some(p) => Some((p.clone(), crate::formats::nav::read_nav(p)?.1)),
                    None => None,
                },
                sensor_truth: match &self.sensor_truth {
                    Some(p) => crate::formats::sensor_errors::read_sensor_errors(p)?,
                    None => Vec::new(),
                },
            },
            fixes,
            config: IntegrationConfig {
                noise,
                scale_factors: self.scale_factors,
                lever_arm: self
                    .lever_arm
                    .map_or(Vector3::zeros(), |t| Vector3::from(t.0)),
                gate,
                reset_after: 5,
                propagation_interval,
                init_pos_std: triple("init-pos-std", &self.init_pos_std, [1.0, 1.0, 1.0])?,
                init_vel_std: triple("init-vel-std", &self.init_vel_std, [0.1, 0.1, 0.1])?,
                // Roll, pitch, yaw std taken about north, east, down (level attitude).
                init_att_std: att.map(f64::to_radians),
                init_sensor_std: None,
                baro: baro_cfg,
            },
        }))
    }
}

/// The value of an aiding option given with a unit (or as a bare SI number), checked
/// finite and not negative; errors name the flag.
pub(super) fn quantity(
    flag: &str,
    v: &Option<String>,
    dim: schuler::units::Dimension,
) -> Result<Option<f64>> {
    let Some(s) = v else { return Ok(None) };
    let x = schuler::units::parse_as_or_si(s, dim).with_context(|| format!("--{flag} {s:?}"))?;
    if !(x.is_finite() && x >= 0.0) {
        bail!("--{flag} must not be negative, got {s:?}");
    }
    Ok(Some(x))
}

/// The outage test's report: the outages, and with a truth the largest horizontal,
/// vertical and attitude errors inside each (for an INS bridging a gap, the error at
/// its end) and the RMS of those maxima, the protocol of the KF-GINS paper; also
/// written to `DIR/outage_test.json`.
pub fn report_outage_test(
    nav: &Path,
    windows: &[(f64, f64)],
    truth: Option<&Path>,
    dir: &Path,
) -> Result<()> {
    println!(
        "outage test: {} outages of {:.0} s",
        windows.len(),
        windows[0].1 - windows[0].0
    );
    let Some(truth) = truth else {
        println!("  (give --truth FILE for the errors in each outage)");
        return Ok(());
    };
    let (_, nav_rows) = crate::formats::nav::read_nav(nav)?;
    let (_, truth_rows) = crate::formats::nav::read_nav(truth)?;
    let c = schuler::analysis::statistics::compare(&nav_rows, &truth_rows, None, None, windows)?;
    let mut json = Vec::new();
    println!(
        "  outage [s]          | horizontal max [m] | vertical max [m] | roll/pitch/yaw max [deg]"
    );
    for o in &c.stats.outages {
        println!(
            "  {:9.1}-{:9.1} | {:18.3} | {:16.3} | {:.4} {:.4} {:.4}",
            o.from_sow,
            o.to_sow,
            o.horizontal,
            o.vertical,
            o.att.roll.to_degrees(),
            o.att.pitch.to_degrees(),
            o.att.yaw.to_degrees()
        );
        json.push(serde_json::json!({
            "from": o.from_sow, "to": o.to_sow, "epochs": o.epochs,
            "horizontal_max_m": o.horizontal, "vertical_max_m": o.vertical,
            "roll_max_deg": o.att.roll.to_degrees(), "pitch_max_deg": o.att.pitch.to_degrees(),
            "yaw_max_deg": o.att.yaw.to_degrees(),
        }));
    }
    let rms = c.stats.outage_rms.map(|o| {
        println!(
            "  RMS of the maxima  | {:18.3} | {:16.3} | {:.4} {:.4} {:.4}",
            o.horizontal,
            o.vertical,
            o.att.roll.to_degrees(),
            o.att.pitch.to_degrees(),
            o.att.yaw.to_degrees()
        );
        serde_json::json!({
            "horizontal_m": o.horizontal, "vertical_m": o.vertical,
            "roll_deg": o.att.roll.to_degrees(), "pitch_deg": o.att.pitch.to_degrees(),
            "yaw_deg": o.att.yaw.to_degrees(),
        })
    });
    let path = dir.join("outage_test.json");
    let text = serde_json::to_string_pretty(
        &serde_json::json!({ "outages": json, "rms_of_maxima": rms }),
    )?;
    std::fs::write(&path, text + "\n").with_context(|| format!("cannot write {}", path.display()))
}
