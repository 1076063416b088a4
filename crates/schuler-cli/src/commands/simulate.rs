//! `schuler simulate --config scenario.toml --out DIR`: trajectory, IMU, GNSS and
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
//!   velocity and its std and the outlier flag);
//! - `baro.csv` (`t,h_m,outlier`);
//! - `scenario.resolved.toml`: every parameter actually used, seed included.
//!
//! Blocks of samples are formatted on the simulator's workers, each block while others
//! are computed or written, and written in time order
//! ([`schuler::sim::run::simulate_with`]). The same scenario and seed give the same
//! bytes.

use crate::fixed::push_fixed;
use crate::output::{ImuDigits, push_imu_line, push_nav_fields};
use anyhow::{Context, Result};
use schuler::sim::receivers::GnssFix;
use schuler::sim::run::{ImuEpoch, ScenarioSpec, SimBlock, simulate_with};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `schuler simulate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scenario TOML (start, motion, imu, optional gnss and baro; see the README).
    #[arg(long, value_name = "FILE")]
    pub config: PathBuf,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Override the scenario's seed.
    #[arg(long)]
    pub seed: Option<u64>,
}

/// A buffered output file that remembers its path for error messages.
struct Out {
    w: BufWriter<File>,
    path: PathBuf,
}

impl Out {
    fn create(dir: &Path, name: &str) -> Result<Self> {
        let path = dir.join(name);
        let f = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(Self {
            w: BufWriter::with_capacity(1 << 16, f),
            path,
        })
    }

    /// Write `bytes`; an error names the file.
    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.w
            .write_all(bytes)
            .map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", self.path.display())))
    }

    fn finish(mut self) -> Result<()> {
        self.w
            .flush()
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// Decimals of the true angular rate in `truth.csv` (1e-12 rad/s).
const W_DECIMALS: usize = 12;
/// Decimals of the true specific force in `truth.csv` (1e-10 m/s^2).
const F_DECIMALS: usize = 10;

/// `bytes` with every space turned into a comma, appended to `out`.
fn push_as_csv(out: &mut Vec<u8>, bytes: &[u8]) {
    let start = out.len();
    out.extend_from_slice(bytes);
    // An unconditional store per byte, so the loop runs on vector lanes.
    for b in &mut out[start..] {
        *b = if *b == b' ' { b',' } else { *b };
    }
}

/// `imu.txt` and `imu.csv` lines of the measured samples of `epochs`. Each number is
/// formatted once: the CSV line is the same bytes with commas for spaces (no number
/// contains either).
fn imu_lines(epochs: &[ImuEpoch], txt: &mut Vec<u8>, csv: &mut Vec<u8>) {
    let start = txt.len();
    for e in epochs {
        push_imu_line(txt, &e.measured, b' ', ImuDigits::Shortest);
        txt.push(b'\n');
    }
    push_as_csv(csv, &txt[start..]);
}

/// `truth.nav` lines (week 0, then `t lat lon h vn ve vd roll pitch yaw`) and
/// `truth.csv` lines (the same after the week, then `w_ib_b` and `f_b`) of `epochs`.
fn truth_lines(epochs: &[ImuEpoch], nav: &mut Vec<u8>, csv: &mut Vec<u8>) {
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

/// `gnss.txt` (`t lat lon h std_n std_e std_d`) and `gnss.csv` (the same, then the
/// velocity, its std and the outlier flag) lines of a fix.
fn gnss_lines(fix: &GnssFix, txt: &mut Vec<u8>, csv: &mut Vec<u8>) {
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
    push_shortest_line(csv, &row, b',');
}

/// The text of one block for every file (one per worker, its memory reused from block
/// to block).
#[derive(Default)]
struct BlockText {
    imu_txt: Vec<u8>,
    imu_csv: Vec<u8>,
    truth_nav: Vec<u8>,
    truth_csv: Vec<u8>,
    gnss_txt: Vec<u8>,
    gnss_csv: Vec<u8>,
    baro_csv: Vec<u8>,
}

impl BlockText {
    /// The lines of `block` for every file.
    fn format(&mut self, block: &SimBlock) {
        for b in [
            &mut self.imu_txt,
            &mut self.imu_csv,
            &mut self.truth_nav,
            &mut self.truth_csv,
            &mut self.gnss_txt,
            &mut self.gnss_csv,
            &mut self.baro_csv,
        ] {
            b.clear();
        }
        imu_lines(&block.imu, &mut self.imu_txt, &mut self.imu_csv);
        truth_lines(&block.imu, &mut self.truth_nav, &mut self.truth_csv);
        for (_, fix) in &block.gnss {
            gnss_lines(fix, &mut self.gnss_txt, &mut self.gnss_csv);
        }
        for (_, r) in &block.baro {
            let row = [r.t, r.h, f64::from(u8::from(r.outlier))];
            push_shortest_line(&mut self.baro_csv, &row, b',');
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
}

impl Files {
    fn create(dir: &Path, gnss: bool, baro: bool) -> Result<Self> {
        let with_header = |name: &str, header: &str| -> Result<Out> {
            let mut o = Out::create(dir, name)?;
            writeln!(o.w, "{header}")
                .with_context(|| format!("cannot write {}", o.path.display()))?;
            Ok(o)
        };
        Ok(Self {
            imu_txt: Out::create(dir, "imu.txt")?,
            imu_csv: with_header(
                "imu.csv",
                "t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z",
            )?,
            truth_nav: Out::create(dir, "truth.nav")?,
            truth_csv: with_header(
                "truth.csv",
                "t,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,w_x,w_y,w_z,f_x,f_y,f_z",
            )?,
            gnss: if gnss {
                Some((
                    Out::create(dir, "gnss.txt")?,
                    with_header(
                        "gnss.csv",
                        "t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m,vn_mps,ve_mps,vd_mps,std_vn_mps,std_ve_mps,std_vd_mps,outlier",
                    )?,
                ))
            } else {
                None
            },
            baro_csv: if baro {
                Some(with_header("baro.csv", "t,h_m,outlier")?)
            } else {
                None
            },
        })
    }

    /// Write a block's text to every file; an error names the file.
    fn write(&mut self, t: &BlockText) -> std::io::Result<()> {
        self.imu_txt.write_all(&t.imu_txt)?;
        self.imu_csv.write_all(&t.imu_csv)?;
        self.truth_nav.write_all(&t.truth_nav)?;
        self.truth_csv.write_all(&t.truth_csv)?;
        if let Some((txt, csv)) = self.gnss.as_mut() {
            txt.write_all(&t.gnss_txt)?;
            csv.write_all(&t.gnss_csv)?;
        }
        if let Some(b) = self.baro_csv.as_mut() {
            b.write_all(&t.baro_csv)?;
        }
        Ok(())
    }

    fn finish(self) -> Result<()> {
        for o in [self.imu_txt, self.imu_csv, self.truth_nav, self.truth_csv] {
            o.finish()?;
        }
        if let Some((a, b)) = self.gnss {
            a.finish()?;
            b.finish()?;
        }
        if let Some(b) = self.baro_csv {
            b.finish()?;
        }
        Ok(())
    }
}

/// Read and parse a scenario file, and the gnss-ins-sim motion file it names (a path
/// relative to the scenario's folder).
pub fn load_scenario(path: &Path) -> Result<ScenarioSpec> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut spec: ScenarioSpec =
        toml::from_str(&text).with_context(|| format!("in {}", path.display()))?;
    if let Some(csv) = &spec.motion_csv {
        let csv_path = path.parent().unwrap_or(Path::new("")).join(csv);
        let text = std::fs::read_to_string(&csv_path)
            .with_context(|| format!("cannot read {}", csv_path.display()))?;
        let def = schuler::sim::gnss_ins_sim::parse(&text)
            .with_context(|| format!("in {}", csv_path.display()))?;
        spec.imported = Some(def);
    }
    Ok(spec)
}

/// Simulate `spec` into `dir`; returns the summary.
pub fn simulate_to_dir(spec: &ScenarioSpec, dir: &Path) -> Result<schuler::sim::run::SimSummary> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut files = Files::create(dir, spec.gnss.is_some(), spec.baro.is_some())?;
    let summary = simulate_with(
        spec,
        |block, text: &mut BlockText| text.format(block),
        |text| files.write(text),
    );
    // Flush what was written even when the simulation stopped early.
    let flushed = files.finish();
    let summary = summary?;
    flushed?;
    let resolved =
        toml::to_string(&spec.resolved()).context("cannot serialize the resolved scenario")?;
    let path = dir.join("scenario.resolved.toml");
    std::fs::write(&path, resolved).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(summary)
}

/// `schuler simulate`.
pub fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let mut spec = load_scenario(&args.config)?;
    if let Some(seed) = args.seed {
        spec.seed = seed;
    }
    let s = simulate_to_dir(&spec, &args.out)
        .with_context(|| format!("in {}", args.config.display()))?;
    println!(
        "simulated {:.1} s: {} IMU samples, {} GNSS fixes, {} baro readings in {:.2} s; files in {}",
        s.t1 - s.t0,
        s.imu_samples,
        s.gnss_fixes,
        s.baro_readings,
        started.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}
