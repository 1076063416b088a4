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
//! The IMU files and the truth files are formatted and written on two threads, block
//! by block, while the simulator computes the next block. The same scenario and seed
//! give the same bytes.

use crate::fixed::push_fixed;
use crate::output::{ImuDigits, push_imu_line, push_nav_fields};
use anyhow::{Context, Result};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::sim::analytic::Kinematics;
use schuler::sim::receivers::{BaroReading, GnssFix};
use schuler::sim::run::{ImuEpoch, ScenarioSpec, SimBlock, SimSink, simulate};
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

/// Appends numbers separated by `sep` in shortest round-trip form.
struct Line {
    buf: Vec<u8>,
    num: zmij::Buffer,
}

impl Line {
    fn new() -> Self {
        Self {
            buf: Vec::with_capacity(512),
            num: zmij::Buffer::new(),
        }
    }

    fn start(&mut self) -> &mut Self {
        self.buf.clear();
        self
    }

    fn num(&mut self, x: f64, sep: u8) -> &mut Self {
        if !self.buf.is_empty() {
            self.buf.push(sep);
        }
        self.buf.extend_from_slice(self.num.format(x).as_bytes());
        self
    }

    fn nums(&mut self, xs: &[f64], sep: u8) -> &mut Self {
        for &x in xs {
            self.num(x, sep);
        }
        self
    }

    fn write(&mut self, out: &mut Out) -> std::io::Result<()> {
        self.buf.push(b'\n');
        out.write_all(&self.buf)
    }
}

/// Decimals of the true angular rate in `truth.csv` (1e-12 rad/s).
const W_DECIMALS: usize = 12;
/// Decimals of the true specific force in `truth.csv` (1e-10 m/s^2).
const F_DECIMALS: usize = 10;

/// `bytes` with every space turned into a comma, appended to `out`.
fn push_as_csv(out: &mut Vec<u8>, bytes: &[u8]) {
    out.extend(bytes.iter().map(|&b| if b == b' ' { b',' } else { b }));
}

/// `imu.txt` and `imu.csv` lines of the measured samples of `epochs`. Each number is
/// formatted once: the CSV line is the same bytes with commas for spaces (no number
/// contains either).
fn imu_lines(epochs: &[ImuEpoch], txt: &mut Vec<u8>, csv: &mut Vec<u8>) {
    for e in epochs {
        let start = txt.len();
        push_imu_line(txt, &e.measured, b' ', ImuDigits::Shortest);
        txt.push(b'\n');
        push_as_csv(csv, &txt[start..]);
    }
}

/// `truth.nav` lines (week 0, then `t lat lon h vn ve vd roll pitch yaw`) and
/// `truth.csv` lines (the same after the week, then `w_ib_b` and `f_b`) of `epochs`.
fn truth_lines(epochs: &[ImuEpoch], nav: &mut Vec<u8>, csv: &mut Vec<u8>) {
    let mut num = zmij::Buffer::new();
    for e in epochs {
        nav.extend_from_slice(b"0 ");
        let start = nav.len();
        nav.extend_from_slice(num.format(e.truth.t).as_bytes());
        push_nav_fields(nav, &e.truth, b' ');
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

/// A per-epoch stream's two files (KF-GINS text and CSV twin) and their text for the
/// current block (the memory reused from block to block).
struct Pair {
    txt: Out,
    csv: Out,
    txt_text: Vec<u8>,
    csv_text: Vec<u8>,
}

impl Pair {
    fn create(dir: &Path, txt: &str, csv: &str, csv_header: &str) -> Result<Self> {
        let mut p = Self {
            txt: Out::create(dir, txt)?,
            csv: Out::create(dir, csv)?,
            txt_text: Vec::new(),
            csv_text: Vec::new(),
        };
        writeln!(p.csv.w, "{csv_header}")
            .with_context(|| format!("cannot write {}", p.csv.path.display()))?;
        Ok(p)
    }

    /// Format `epochs` with `lines` and write the text to both files; an error names
    /// the file.
    fn write(
        &mut self,
        epochs: &[ImuEpoch],
        lines: fn(&[ImuEpoch], &mut Vec<u8>, &mut Vec<u8>),
    ) -> std::io::Result<()> {
        self.txt_text.clear();
        self.csv_text.clear();
        lines(epochs, &mut self.txt_text, &mut self.csv_text);
        self.txt.write_all(&self.txt_text)?;
        self.csv.write_all(&self.csv_text)
    }

    fn finish(self) -> Result<()> {
        self.txt.finish()?;
        self.csv.finish()
    }
}

/// Writes every stream to its files.
struct FileSink {
    imu: Pair,
    truth: Pair,
    gnss_txt: Option<(Out, Out)>,
    baro_csv: Option<Out>,
    line: Line,
}

impl FileSink {
    fn create(dir: &Path, gnss: bool, baro: bool) -> Result<Self> {
        let mut s = Self {
            imu: Pair::create(
                dir,
                "imu.txt",
                "imu.csv",
                "t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z",
            )?,
            truth: Pair::create(
                dir,
                "truth.nav",
                "truth.csv",
                "t,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,w_x,w_y,w_z,f_x,f_y,f_z",
            )?,
            gnss_txt: if gnss {
                Some((Out::create(dir, "gnss.txt")?, Out::create(dir, "gnss.csv")?))
            } else {
                None
            },
            baro_csv: if baro {
                Some(Out::create(dir, "baro.csv")?)
            } else {
                None
            },
            line: Line::new(),
        };
        let header = |o: &mut Out, h: &str| {
            writeln!(o.w, "{h}").with_context(|| format!("cannot write {}", o.path.display()))
        };
        if let Some((_, csv)) = s.gnss_txt.as_mut() {
            header(
                csv,
                "t,lat_deg,lon_deg,h_m,std_n_m,std_e_m,std_d_m,vn_mps,ve_mps,vd_mps,std_vn_mps,std_ve_mps,std_vd_mps,outlier",
            )?;
        }
        if let Some(b) = s.baro_csv.as_mut() {
            header(b, "t,h_m,outlier")?;
        }
        Ok(s)
    }

    fn finish(self) -> Result<()> {
        self.imu.finish()?;
        self.truth.finish()?;
        if let Some((a, b)) = self.gnss_txt {
            a.finish()?;
            b.finish()?;
        }
        if let Some(b) = self.baro_csv {
            b.finish()?;
        }
        Ok(())
    }
}

impl SimSink for FileSink {
    fn imu(
        &mut self,
        exact: &ImuSample,
        measured: &ImuSample,
        truth: &NavState,
        kin: &Kinematics,
    ) -> std::io::Result<()> {
        let epoch = [ImuEpoch {
            exact: *exact,
            measured: *measured,
            truth: *truth,
            kin: *kin,
        }];
        self.imu.write(&epoch, imu_lines)?;
        self.truth.write(&epoch, truth_lines)
    }

    /// The GNSS and barometer epochs (a few) as they come; the IMU files and the truth
    /// files each formatted and written on a thread of their own: the same bytes as
    /// one epoch at a time.
    fn block(&mut self, block: &SimBlock) -> std::io::Result<()> {
        for (_, fix) in &block.gnss {
            self.gnss(fix)?;
        }
        for (_, r) in &block.baro {
            self.baro(r)?;
        }
        let (imu, truth) = (&mut self.imu, &mut self.truth);
        std::thread::scope(|scope| {
            let job = scope.spawn(|| imu.write(&block.imu, imu_lines));
            let truth_written = truth.write(&block.imu, truth_lines);
            let imu_written = job.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
            imu_written.and(truth_written)
        })
    }

    fn gnss(&mut self, fix: &GnssFix) -> std::io::Result<()> {
        let Some((txt, csv)) = self.gnss_txt.as_mut() else {
            return Ok(());
        };
        let pos = [
            fix.pos.lat.to_degrees(),
            fix.pos.lon.to_degrees(),
            fix.pos.h,
        ];
        let sd = [fix.pos_std.x, fix.pos_std.y, fix.pos_std.z];
        self.line
            .start()
            .num(fix.t, b' ')
            .nums(&pos, b' ')
            .nums(&sd, b' ')
            .write(txt)?;
        let v = [
            fix.v_n.x,
            fix.v_n.y,
            fix.v_n.z,
            fix.vel_std.x,
            fix.vel_std.y,
            fix.vel_std.z,
        ];
        self.line
            .start()
            .num(fix.t, b',')
            .nums(&pos, b',')
            .nums(&sd, b',')
            .nums(&v, b',')
            .num(f64::from(u8::from(fix.outlier)), b',')
            .write(csv)
    }

    fn baro(&mut self, r: &BaroReading) -> std::io::Result<()> {
        let Some(out) = self.baro_csv.as_mut() else {
            return Ok(());
        };
        self.line
            .start()
            .num(r.t, b',')
            .num(r.h, b',')
            .num(f64::from(u8::from(r.outlier)), b',')
            .write(out)
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
    let mut sink = FileSink::create(dir, spec.gnss.is_some(), spec.baro.is_some())?;
    let summary = simulate(spec, &mut sink);
    // Flush what was written even when the simulation stopped early.
    let flushed = sink.finish();
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
