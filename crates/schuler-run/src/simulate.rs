//! A scenario simulated into files (`schuler simulate`): trajectory, IMU, GNSS and
//! barometer data with exact truth, in the formats `schuler nav` and KF-GINS read.
//!
//! Files:
//! - `imu.txt` (KF-GINS: `t dtheta_xyz dvel_xyz`, measured) and `imu.csv` (the same
//!   with a header), every number in shortest round-trip form: the file reads back to
//!   the simulated f64s exactly;
//! - `truth.nav` (KF-GINS navigation format at the IMU rate) and `truth.csv` (adds the
//!   true angular rate `w_ib_b` and specific force `f_b` at each epoch): time in
//!   shortest round-trip form (the IMU file's time tags exactly), the state with the
//!   decimals of `schuler nav`'s own output (1e-11 deg ≈ 1 µm of latitude and
//!   longitude, 1 µm height, 1 µm/s velocity, 1e-9 deg attitude), `w_ib_b` to 1e-12
//!   rad/s (2e-7 deg/h) and `f_b` to 1e-10 m/s^2 (1e-11 g): rounding leaves at most half
//!   of each, below what any navigation error worth measuring comes to (the
//!   perfect-sensor round trip through `schuler nav` stays at a fraction of a
//!   millimetre after 30 min) and far below the biases of a navigation-grade IMU
//!   (0.01 deg/h, 50 µg);
//! - `gnss.txt` (KF-GINS: `t lat lon h std_n std_e std_d`) and `gnss.csv` (adds the
//!   velocity and its std when the scenario measures it, `gnss.velocity_std`, and the
//!   outlier flag: a receiver simulated without it reports no velocity, rather than
//!   the true one with a standard deviation of 0, which no reader can weigh);
//! - `baro.csv` (`t,h_m,outlier`);
//! - `imu_err_truth.txt`: the true IMU errors once a second in the layout of `schuler
//!   nav`'s `imu_err.txt` (`t`, gyro bias [deg/h], accelerometer bias [mGal], gyro and
//!   accelerometer scale factors [ppm]), for `schuler nav --sensor-truth`;
//! - with `[gnss.raw]`: `gnss_obs.rnx`, the raw observations (RINEX 3.04: C1C, D1C,
//!   S1C per signal; [`schuler::sim::raw_gnss`]) at the receiver clock's epochs,
//!   `gnss_nav.rnx`, the navigation file they were made from (the scenario's, as
//!   plain text; or the nominal constellation's, written and read back so that the
//!   file and the observations agree exactly), and `gnss_raw_truth.csv`
//!   (`t_rx,t_gps,clock_bias_s,clock_drift,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,sats`: the
//!   epoch's receiver time and true GPS time [s of week], the receiver clock, the
//!   antenna's ECEF position and velocity, the satellites seen);
//! - `scenario.resolved.toml`: every parameter actually used, seed included.
//!
//! Blocks of samples are formatted on the simulator's workers, each block while others
//! are computed or written, and written in time order
//! ([`schuler::sim::run::simulate_with`]). The same scenario and seed give the same
//! bytes.

use crate::drive::{imu_err_row, push_table_row};
use crate::scenario::simulates_gnss_velocity;

use anyhow::{Context, Result};
use schuler::sim::receivers::GnssFix;
use schuler::sim::run::{ImuEpoch, ScenarioSpec, SimBlock, simulate_with};
use schuler_io::fixed::{Line, Twin, Words, push_fixed, put_bytes, put_field};
use schuler_io::line_file::LineFile;
use schuler_io::output::{push_nav_fields, put_imu_increments, put_nav_fields};
use schuler_io::text_block::{TextBlock, window};
use std::path::Path;

/// An output file: whole blocks of lines, cut back to the last whole line if a write
/// fails; errors name the file.
type Out = LineFile;
/// Decimals of the true angular rate in `truth.csv` (1e-12 rad/s).
const W_DECIMALS: usize = 12;
/// Decimals of the true specific force in `truth.csv` (1e-10 m/s^2).
const F_DECIMALS: usize = 10;

/// Windows for one line ([`Line`]: the longest line, a power of two, and 8 bytes more):
/// an IMU line (7 shortest numbers of at most 24 bytes, with separators and newline
/// 175 bytes), a `truth.nav` line after its `0 ` (the time, 9 fixed-decimal fields of
/// at most 17 bytes, each with its separator: 188 bytes) and a `truth.csv` line (the
/// time, 15 such fields: 296 bytes).
const IMU_WINDOW: usize = 256 + 8;
const NAV_WINDOW: usize = 256 + 8;
const CSV_WINDOW: usize = 512 + 8;

/// The lines of `epochs` in `imu.txt` and `imu.csv` (`t dtheta_xyz dvel_xyz`, every
/// number in shortest round-trip form), `truth.nav` (week 0, then `t lat lon h vn ve
/// vd roll pitch yaw`) and `truth.csv` (the same after the week, then `w_ib_b` and
/// `f_b`). Each number is formatted once: a CSV line is stored with its text twin
/// ([`Twin`]), commas for spaces (no number contains either), and the truth's time is
/// the IMU line's when it is the same f64.
fn epoch_lines(
    epochs: &[ImuEpoch],
    imu_txt: &mut TextBlock,
    imu_csv: &mut TextBlock,
    nav: &mut TextBlock,
    csv: &mut TextBlock,
) {
    let (mut time, mut num) = (zmij::Buffer::new(), zmij::Buffer::new());
    let mut rest = epochs;
    while !rest.is_empty() {
        // The scratch of every line left, taken once: a line's window is a slice of it
        // at a position kept in a register.
        let lines = rest.len();
        let imu_txt_scratch = imu_txt.scratch(lines * IMU_WINDOW);
        let imu_csv_scratch = imu_csv.scratch(lines * IMU_WINDOW);
        let nav_scratch = nav.scratch(lines * (2 + NAV_WINDOW));
        let csv_scratch = csv.scratch(lines * CSV_WINDOW);
        let (mut imu_len, mut nav_len, mut csv_len) = (0, 0, 0);
        let mut declined = None;
        for (k, e) in rest.iter().enumerate() {
            let t = time.format(e.measured.t).as_bytes();
            let mut w = Twin(
                Line {
                    bytes: window::<IMU_WINDOW>(imu_txt_scratch, imu_len),
                    sep: b' ',
                },
                Line {
                    bytes: window::<IMU_WINDOW>(imu_csv_scratch, imu_len),
                    sep: b',',
                },
            );
            let end = put_bytes(&mut w, 0, t);
            let end = put_imu_increments(&mut w, end, &e.measured, &mut num);
            w.put(end, u64::from(b'\n'));
            imu_len += Line::<IMU_WINDOW>::end(end) + 1;

            let t = if e.truth.t.to_bits() == e.measured.t.to_bits() {
                t
            } else {
                num.format(e.truth.t).as_bytes()
            };
            let (week, nav_window) = nav_scratch[nav_len..].split_at_mut(2);
            week.copy_from_slice(b"0 ");
            let lengths = truth_line(e, t, window(nav_window, 0), window(csv_scratch, csv_len));
            let Some((nav_line, csv_line)) = lengths else {
                declined = Some(k);
                break;
            };
            nav_len += 2 + nav_line;
            csv_len += csv_line;
        }
        imu_txt.advance(imu_len);
        imu_csv.advance(imu_len);
        nav.advance(nav_len);
        csv.advance(csv_len);
        let Some(k) = declined else {
            break;
        };
        // The truth lines of this epoch through the Vec writers.
        let e = &rest[k];
        let (mut nav_line, mut csv_line) = (Vec::new(), Vec::new());
        truth_line_general(
            e,
            num.format(e.truth.t).as_bytes(),
            &mut nav_line,
            &mut csv_line,
        );
        nav.extend(&nav_line);
        csv.extend(&csv_line);
        rest = &rest[k + 1..];
    }
}

/// The `truth.nav` line of `e` after its week and the `truth.csv` line, with time
/// text `t`, into the windows `nav` and `csv`; their lengths, or `None` when a number
/// is outside [`put_nav_fields`]' range (then [`truth_line_general`] writes them).
#[inline(always)]
fn truth_line(
    e: &ImuEpoch,
    t: &[u8],
    nav: &mut [u8; NAV_WINDOW],
    csv: &mut [u8; CSV_WINDOW],
) -> Option<(usize, usize)> {
    let mut w = Twin(
        Line {
            bytes: nav,
            sep: b' ',
        },
        Line {
            bytes: csv,
            sep: b',',
        },
    );
    let end = put_bytes(&mut w, 0, t);
    let end = put_nav_fields(&mut w, end, &e.truth, &e.euler)?;
    w.0.put(end, u64::from(b'\n'));
    let nav_len = Line::<NAV_WINDOW>::end(end) + 1;
    let mut csv = w.1;
    let (r, f) = (e.kin.w_ib_b, e.kin.f_b);
    let mut field = |pos: usize, x: f64, decimals: usize| put_field(&mut csv, pos, x, decimals);
    let end = field(end, r.x, W_DECIMALS)?;
    let end = field(end, r.y, W_DECIMALS)?;
    let end = field(end, r.z, W_DECIMALS)?;
    let end = field(end, f.x, F_DECIMALS)?;
    let end = field(end, f.y, F_DECIMALS)?;
    let end = field(end, f.z, F_DECIMALS)?;
    csv.put(end, u64::from(b'\n'));
    Some((nav_len, Line::<CSV_WINDOW>::end(end) + 1))
}

/// [`truth_line`] for any numbers, whole lines through [`push_nav_fields`] and
/// [`push_fixed`].
fn truth_line_general(e: &ImuEpoch, t: &[u8], nav: &mut Vec<u8>, csv: &mut Vec<u8>) {
    nav.extend_from_slice(b"0 ");
    nav.extend_from_slice(t);
    push_nav_fields(nav, &e.truth, &e.euler, b' ');
    nav.push(b'\n');
    csv.extend_from_slice(t);
    push_nav_fields(csv, &e.truth, &e.euler, b',');
    let (w, f) = (e.kin.w_ib_b, e.kin.f_b);
    for x in [w.x, w.y, w.z] {
        csv.push(b',');
        push_fixed(csv, x, W_DECIMALS);
    }
    for x in [f.x, f.y, f.z] {
        csv.push(b',');
        push_fixed(csv, x, F_DECIMALS);
    }
    csv.push(b'\n');
}

/// Append `xs` in shortest round-trip form separated by `sep`, then a newline.
fn push_shortest_line(out: &mut Vec<u8>, xs: &[f64], sep: u8) {
    let mut num = zmij::Buffer::new();
    for (i, &x) in xs.iter().enumerate() {
        if i > 0 {
            out.push(sep);
        }
        out.extend_from_slice(num.format(x).as_bytes());
    }
    out.push(b'\n');
}

/// `gnss.csv`'s header (velocity columns with `velocity`).
fn gnss_csv_header(velocity: bool) -> String {
    let velocity = if velocity {
        ",vn_mps,ve_mps,vd_mps,std_vn_mps,std_ve_mps,std_vd_mps"
    } else {
        ""
    };
    format!("t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m{velocity},outlier")
}

/// `gnss.txt` (`t lat lon h std_n std_e std_d`) and `gnss.csv` (the same, then with
/// `velocity` the velocity and its std, then the outlier flag) lines of a fix.
fn gnss_lines(fix: &GnssFix, velocity: bool, txt: &mut Vec<u8>, csv: &mut Vec<u8>) {
    let (p, sd, v, vsd) = (fix.pos, fix.pos_std, fix.v_n, fix.vel_std);
    let row = [
        fix.t,
        p.lat.to_degrees(),
        p.lon.to_degrees(),
        p.h,
        sd.x,
        sd.y,
        sd.z,
        v.x,
        v.y,
        v.z,
        vsd.x,
        vsd.y,
        vsd.z,
        f64::from(u8::from(fix.outlier)),
    ];
    push_shortest_line(txt, &row[..7], b' ');
    if velocity {
        push_shortest_line(csv, &row, b',');
    } else {
        push_shortest_line(csv, &[&row[..7], &row[13..]].concat(), b',');
    }
}

/// The text of one block for every file (one per worker, its memory reused from block
/// to block).
#[derive(Default)]
struct BlockText {
    imu_txt: TextBlock,
    imu_csv: TextBlock,
    truth_nav: TextBlock,
    truth_csv: TextBlock,
    gnss_txt: Vec<u8>,
    gnss_csv: Vec<u8>,
    baro_csv: Vec<u8>,
    imu_err: Vec<u8>,
    /// The block's IMU samples and the time of its last [s].
    samples: u64,
    last_t: f64,
}

impl BlockText {
    /// The lines of `block` for every file (`gnss_velocity`: [`simulates_gnss_velocity`]).
    fn format(&mut self, block: &SimBlock, gnss_velocity: bool) {
        for t in [
            &mut self.imu_txt,
            &mut self.imu_csv,
            &mut self.truth_nav,
            &mut self.truth_csv,
        ] {
            t.clear();
        }
        for b in [
            &mut self.gnss_txt,
            &mut self.gnss_csv,
            &mut self.baro_csv,
            &mut self.imu_err,
        ] {
            b.clear();
        }
        // Room for the windows of every line: the block's text takes memory once.
        let lines = block.imu.len();
        self.samples = lines as u64;
        self.last_t = block.imu.last().map_or(f64::NAN, |e| e.truth.t);
        self.imu_txt.reserve(lines * IMU_WINDOW);
        self.imu_csv.reserve(lines * IMU_WINDOW);
        self.truth_nav.reserve(lines * (2 + NAV_WINDOW));
        self.truth_csv.reserve(lines * CSV_WINDOW);
        epoch_lines(
            &block.imu,
            &mut self.imu_txt,
            &mut self.imu_csv,
            &mut self.truth_nav,
            &mut self.truth_csv,
        );
        for (_, fix) in &block.gnss {
            gnss_lines(fix, gnss_velocity, &mut self.gnss_txt, &mut self.gnss_csv);
        }
        for (_, r) in &block.baro {
            let row = [r.t, r.h, f64::from(u8::from(r.outlier))];
            push_shortest_line(&mut self.baro_csv, &row, b',');
        }
        for (_, e) in &block.imu_errors {
            push_table_row(&mut self.imu_err, e.t, &imu_err_row(&e.errors));
        }
    }
}

/// Every output file.
struct Files {
    imu_txt: Out,
    imu_csv: Out,
    truth_nav: Out,
    truth_csv: Out,
    gnss: Option<(Out, Out)>,
    baro_csv: Option<Out>,
    imu_err: Out,
}

impl Files {
    /// The files in `dir`; GNSS ones with `gnss` (`Some(velocity)`), `baro.csv` with
    /// `baro`.
    fn create(dir: &Path, gnss: Option<bool>, baro: bool) -> Result<Self> {
        let with_header = |name: &str, header: &str| -> Result<Out> {
            let mut o = Out::create(dir.join(name))?;
            o.append(format!("{header}\n").as_bytes())?;
            Ok(o)
        };
        Ok(Self {
            imu_txt: Out::create(dir.join("imu.txt"))?,
            imu_csv: with_header(
                "imu.csv",
                "t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z",
            )?,
            truth_nav: Out::create(dir.join("truth.nav"))?,
            truth_csv: with_header(
                "truth.csv",
                "t,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,w_x,w_y,w_z,f_x,f_y,f_z",
            )?,
            gnss: match gnss {
                Some(velocity) => Some((
                    Out::create(dir.join("gnss.txt"))?,
                    with_header("gnss.csv", &gnss_csv_header(velocity))?,
                )),
                None => None,
            },
            baro_csv: if baro {
                Some(with_header("baro.csv", "t,h_m,outlier")?)
            } else {
                None
            },
            imu_err: Out::create(dir.join("imu_err_truth.txt"))?,
        })
    }

    /// Write a block's text to every file; an error names the file.
    fn write(&mut self, t: &BlockText) -> std::io::Result<()> {
        self.imu_txt.append(t.imu_txt.as_bytes())?;
        self.imu_csv.append(t.imu_csv.as_bytes())?;
        self.truth_nav.append(t.truth_nav.as_bytes())?;
        self.truth_csv.append(t.truth_csv.as_bytes())?;
        if let Some((txt, csv)) = self.gnss.as_mut() {
            txt.append(&t.gnss_txt)?;
            csv.append(&t.gnss_csv)?;
        }
        if let Some(b) = self.baro_csv.as_mut() {
            b.append(&t.baro_csv)?;
        }
        self.imu_err.append(&t.imu_err)?;
        Ok(())
    }
}

/// Simulate `spec` into `dir`; returns the summary.
pub fn simulate_to_dir(spec: &ScenarioSpec, dir: &Path) -> Result<schuler::sim::run::SimSummary> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let velocity = simulates_gnss_velocity(spec);
    let gnss = spec.gnss.is_some().then_some(velocity);
    let mut files = Files::create(dir, gnss, spec.baro.is_some())?;
    let (mut samples, mut written_to) = (0u64, f64::NAN);
    let summary = simulate_with(
        spec,
        |block, text: &mut BlockText| text.format(block, velocity),
        |text| {
            files.write(text)?;
            (samples, written_to) = (samples + text.samples, text.last_t);
            // A signal stops the run after a whole block: every file ends there.
            match crate::interrupt::requested() {
                Some(_) => Err(std::io::Error::from(std::io::ErrorKind::Interrupted)),
                None => Ok(()),
            }
        },
    );
    // Every block written is in the files, whole, even when the simulation stopped
    // early.
    drop(files);
    if let (Err(_), Some(i)) = (&summary, crate::interrupt::requested()) {
        return Err(anyhow::Error::new(i).context(format!(
            "stopped at t = {written_to} s: the files in {} hold the {samples} IMU samples up to \
             there, with the GNSS, barometer and sensor-error lines up to the same time",
            dir.display()
        )));
    }
    let summary = summary?;
    if spec.gnss.as_ref().is_some_and(|g| g.raw.is_some()) {
        write_raw_gnss(spec, dir)?;
    }
    let resolved =
        toml::to_string(&spec.resolved()).context("cannot serialize the resolved scenario")?;
    let path = dir.join("scenario.resolved.toml");
    schuler_io::line_file::write_whole(&path, resolved)?;
    Ok(summary)
}

/// The raw GNSS files of `spec` (its `[gnss.raw]`) in `dir`: `gnss_nav.rnx`,
/// `gnss_obs.rnx`, `gnss_raw_truth.csv`.
fn write_raw_gnss(spec: &ScenarioSpec, dir: &Path) -> Result<()> {
    use schuler::sim::raw_gnss::trajectory::{nominal_data, prepare, simulate_raw};
    use schuler_io::formats::rinex::write::{ObsFileInfo, ObsWriter, copy_plain, write_gps_nav};
    let (raw, model, antenna) = prepare(spec)?;
    let nav_path = dir.join("gnss_nav.rnx");
    let data = match &raw.data {
        Some(d) => {
            if let Some(file) = &d.file {
                copy_plain(file, &nav_path)?;
            }
            d.clone()
        }
        None => {
            let made = nominal_data(&model, antenna.span());
            let ephemerides = made.store.sats().flat_map(|s| made.store.of(s));
            let mut text = Vec::new();
            write_gps_nav(
                &mut text,
                "schuler simulate",
                made.klobuchar.as_ref(),
                ephemerides,
            )?;
            schuler_io::line_file::write_whole(&nav_path, text)?;
            // The observations from the file as read back: the same numbers exactly.
            let (_, klobuchar, store) = schuler_io::formats::rinex::nav::read_store(&nav_path)?;
            schuler::sim::raw_gnss::spec::NavData {
                store,
                klobuchar,
                file: None,
            }
        }
    };
    let epochs = simulate_raw(spec, &data)?;
    let first = epochs
        .first()
        .map_or([0.0; 3], |e| [e.r_e.x, e.r_e.y, e.r_e.z]);
    let obs_path = dir.join("gnss_obs.rnx");
    let file = std::fs::File::create(&obs_path)
        .with_context(|| format!("cannot create {}", obs_path.display()))?;
    let mut w = ObsWriter::new(
        std::io::BufWriter::new(file),
        ObsFileInfo {
            marker: "SCHULER-SIM".into(),
            approx_position: first,
            program: "schuler simulate".into(),
            interval: Some(model.interval),
            signals: model.signals.clone(),
        },
    );
    let mut truth =
        b"t_rx,t_gps,clock_bias_s,clock_drift,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,sats\n".to_vec();
    for e in &epochs {
        w.epoch(&e.epoch)
            .with_context(|| format!("cannot write {}", obs_path.display()))?;
        let week_start = schuler::gnss::GpsTime::new(model.week, 0.0);
        let row = [
            e.epoch.t.diff_s(week_start),
            e.t_true.diff_s(week_start),
            e.clock_bias,
            e.clock_drift,
            e.r_e.x,
            e.r_e.y,
            e.r_e.z,
            e.v_e.x,
            e.v_e.y,
            e.v_e.z,
            e.epoch.sats().len() as f64,
        ];
        push_shortest_line(&mut truth, &row, b',');
    }
    w.finish()
        .with_context(|| format!("cannot write {}", obs_path.display()))?;
    schuler_io::line_file::write_whole(&dir.join("gnss_raw_truth.csv"), truth)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use schuler::earth::Geodetic;
    use schuler::imu::ImuSample;
    use schuler::nav::NavState;
    use schuler::rotation::Euler;
    use schuler::sim::analytic::Kinematics;
    use schuler_io::output::{ImuDigits, push_imu_line};

    /// The text writers before the fixed-size windows (commit 97e21d9), kept as the
    /// oracle: every line through the Vec writers, the CSV as the text with commas.
    mod previous {
        use super::*;

        fn push_as_csv(out: &mut Vec<u8>, bytes: &[u8]) {
            let start = out.len();
            out.extend_from_slice(bytes);
            for b in &mut out[start..] {
                *b = if *b == b' ' { b',' } else { *b };
            }
        }

        pub fn imu_lines(epochs: &[ImuEpoch], txt: &mut Vec<u8>, csv: &mut Vec<u8>) {
            let start = txt.len();
            for e in epochs {
                push_imu_line(txt, &e.measured, b' ', ImuDigits::Shortest);
                txt.push(b'\n');
            }
            push_as_csv(csv, &txt[start..]);
        }

        pub fn truth_lines(epochs: &[ImuEpoch], nav: &mut Vec<u8>, csv: &mut Vec<u8>) {
            let mut num = zmij::Buffer::new();
            for e in epochs {
                nav.extend_from_slice(b"0 ");
                let start = nav.len();
                nav.extend_from_slice(num.format(e.truth.t).as_bytes());
                push_nav_fields(nav, &e.truth, &e.euler, b' ');
                push_as_csv(csv, &nav[start..]);
                nav.push(b'\n');
                let (w, f) = (e.kin.w_ib_b, e.kin.f_b);
                for x in [w.x, w.y, w.z] {
                    csv.push(b',');
                    push_fixed(csv, x, W_DECIMALS);
                }
                for x in [f.x, f.y, f.z] {
                    csv.push(b',');
                    push_fixed(csv, x, F_DECIMALS);
                }
                csv.push(b'\n');
            }
        }
    }

    /// The block's text against the previous writers', file by file.
    fn assert_same_text(block: &SimBlock, text: &BlockText) {
        let [mut imu_txt, mut imu_csv, mut nav, mut csv] = [(); 4].map(|()| Vec::new());
        previous::imu_lines(&block.imu, &mut imu_txt, &mut imu_csv);
        previous::truth_lines(&block.imu, &mut nav, &mut csv);
        let same = |name: &str, got: &TextBlock, want: &[u8]| {
            assert!(
                got.as_bytes() == want,
                "{name} differs:\n{}\nwanted\n{}",
                String::from_utf8_lossy(got.as_bytes()),
                String::from_utf8_lossy(want)
            );
        };
        same("imu.txt", &text.imu_txt, &imu_txt);
        same("imu.csv", &text.imu_csv, &imu_csv);
        same("truth.nav", &text.truth_nav, &nav);
        same("truth.csv", &text.truth_csv, &csv);
    }

    /// An epoch at time `t` with its numbers taken from `x` in turn (cycled).
    fn epoch(t: f64, x: &[f64]) -> ImuEpoch {
        let at = |k: usize| x[k % x.len()];
        let v3 = |k: usize| Vector3::new(at(k), at(k + 1), at(k + 2));
        let sample = ImuSample {
            t,
            dt: 0.001,
            dtheta: v3(0),
            dvel: v3(3),
        };
        let euler = Euler::new(at(18), at(19), at(20));
        ImuEpoch {
            exact: sample,
            measured: sample,
            truth: NavState::new(t, Geodetic::new(at(15), at(16), at(17)), v3(12), euler),
            kin: Kinematics {
                w_ib_b: v3(6),
                f_b: v3(9),
            },
            euler,
        }
    }

    /// Epochs of every kind: ordinary numbers, signed zeros, the extremes of every
    /// field's width, values the fast writers decline (NaN, infinities, 1e300, a
    /// latitude past the pole), a truth time other than the IMU time; the same bytes
    /// as the previous writers, line by line and as blocks, in scratch with old bytes.
    #[test]
    fn same_bytes_as_the_previous_writers() {
        let ordinary = [
            std::f64::consts::FRAC_PI_4,
            0.12217304763960307,
            300.0,
            -1.0e-7,
            29.99999949999,
            -9.80665,
            4.9e-6,
            -0.0,
            0.0,
            1.5e-5,
        ];
        let wide = [
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            -9999.999999,
            -1.0 / 3.0,
        ];
        let mut epochs = Vec::new();
        for k in 0..200 {
            let t = f64::from(k) * 0.001;
            let mut x = ordinary.to_vec();
            x.rotate_left(k as usize % ordinary.len());
            if k % 7 == 0 {
                x.extend(wide);
            }
            epochs.push(epoch(t, &x));
        }
        for (k, bad) in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            -4e15,
            5e-324,
            1.6,
            -1.6,
        ]
        .into_iter()
        .enumerate()
        {
            for j in 0..22 {
                let mut x = ordinary.to_vec();
                x[j % ordinary.len()] = bad;
                let mut e = epoch(1.0 + k as f64, &x);
                match j {
                    12..=14 => e.kin.w_ib_b[j - 12] = bad,
                    15..=17 => e.kin.f_b[j - 15] = bad,
                    18 => e.truth.pos.lat = bad,
                    19 => e.truth.pos.h = bad,
                    20 => e.truth.t = bad,
                    _ => e.truth.v_n[j % 3] = bad,
                }
                epochs.push(e);
            }
        }
        let mut e = epoch(0.1 + 0.2, &ordinary);
        e.truth.t = 0.3;
        epochs.push(e);

        let mut text = BlockText::default();
        for lines in [1, 3, epochs.len()] {
            for chunk in epochs.chunks(lines) {
                let block = SimBlock {
                    imu: chunk.to_vec(),
                    ..SimBlock::default()
                };
                text.format(&block, true);
                assert_same_text(&block, &text);
            }
        }
    }

    /// A simulated flight (turn, climb, hold at 1 kHz, a tactical IMU): every block's
    /// text as the previous writers made it.
    #[test]
    fn simulated_blocks_same_bytes_as_the_previous_writers() {
        let spec: ScenarioSpec = toml::from_str(
            r#"
seed = 3
[start]
position = ["45 deg", "7 deg", "300 m"]
attitude = ["0 deg", "0 deg", "0 deg"]
speed = "30 m/s"
[[motion]]
type = "turn"
angle = "90 deg"
bank = "20 deg"
[[motion]]
type = "climb"
to_height = "400 m"
[imu]
rate_hz = 1000
preset = "tactical"
"#,
        )
        .expect("scenario");
        let summary = simulate_with(
            &spec,
            |block, text: &mut BlockText| {
                text.format(block, true);
                assert_same_text(block, text);
            },
            |_| Ok(()),
        )
        .expect("simulated");
        assert!(summary.imu_samples > 10_000);
    }
}
