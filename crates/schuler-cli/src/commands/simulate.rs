//! `schuler simulate --config scenario.toml --out DIR`: trajectory, IMU, GNSS and
//! barometer data with exact truth, in the formats `schuler nav` and KF-GINS read.
//!
//! Files (numbers in shortest round-trip form, so nothing is lost):
//! - `imu.txt` (KF-GINS: `t dtheta_xyz dvel_xyz`, measured) and `imu.csv` (the same
//!   with a header);
//! - `truth.nav` (KF-GINS navigation format at the IMU rate) and `truth.csv` (adds the
//!   true angular rate `w_ib_b` and specific force `f_b` at each epoch);
//! - `gnss.txt` (KF-GINS: `t lat lon h std_n std_e std_d`) and `gnss.csv` (adds the
//!   velocity and its std and the outlier flag);
//! - `baro.csv` (`t,h_m,outlier`);
//! - `scenario.resolved.toml`: every parameter actually used, seed included.
//!
//! The same scenario and seed give the same bytes.

use crate::output::{ImuDigits, push_imu_line};
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
        out.w.write_all(&self.buf)
    }
}

/// Output columns of a navigation state in KF-GINS units (deg, m, m/s, deg; yaw in
/// [0, 360)).
fn nav_fields(s: &NavState) -> [f64; 9] {
    let e = s.euler();
    [
        s.pos.lat.to_degrees(),
        s.pos.lon.to_degrees(),
        s.pos.h,
        s.v_n.x,
        s.v_n.y,
        s.v_n.z,
        e.roll.to_degrees(),
        e.pitch.to_degrees(),
        e.heading_0_2pi().to_degrees(),
    ]
}

/// The text of consecutive IMU epochs for the four per-epoch files.
///
/// Each number is formatted once: the CSV twin of a line is the same bytes with
/// commas for spaces (no number contains either).
#[derive(Default)]
struct EpochText {
    imu_txt: Vec<u8>,
    imu_csv: Vec<u8>,
    truth_nav: Vec<u8>,
    truth_csv: Vec<u8>,
}

/// `bytes` with every space turned into a comma, appended to `out`.
fn push_as_csv(out: &mut Vec<u8>, bytes: &[u8]) {
    out.extend(bytes.iter().map(|&b| if b == b' ' { b',' } else { b }));
}

impl EpochText {
    fn clear(&mut self) {
        self.imu_txt.clear();
        self.imu_csv.clear();
        self.truth_nav.clear();
        self.truth_csv.clear();
    }

    /// Append the lines of `epochs`.
    fn push(&mut self, epochs: &[ImuEpoch]) {
        let mut num = zmij::Buffer::new();
        for e in epochs {
            // imu.txt (KF-GINS) and imu.csv: the measured sample.
            let start = self.imu_txt.len();
            push_imu_line(&mut self.imu_txt, &e.measured, b' ', ImuDigits::Shortest);
            self.imu_txt.push(b'\n');
            push_as_csv(&mut self.imu_csv, &self.imu_txt[start..]);
            // truth.nav: week 0, then `t lat lon h vn ve vd roll pitch yaw`; truth.csv:
            // the same after the week, then w_ib_b and f_b.
            self.truth_nav.extend_from_slice(b"0 ");
            let start = self.truth_nav.len();
            self.truth_nav
                .extend_from_slice(num.format(e.truth.t).as_bytes());
            for x in nav_fields(&e.truth) {
                self.truth_nav.push(b' ');
                self.truth_nav.extend_from_slice(num.format(x).as_bytes());
            }
            push_as_csv(&mut self.truth_csv, &self.truth_nav[start..]);
            self.truth_nav.push(b'\n');
            let (w, f) = (e.kin.w_ib_b, e.kin.f_b);
            for x in [w.x, w.y, w.z, f.x, f.y, f.z] {
                self.truth_csv.push(b',');
                self.truth_csv.extend_from_slice(num.format(x).as_bytes());
            }
            self.truth_csv.push(b'\n');
        }
    }
}

/// Writes every stream to its files.
struct FileSink {
    imu_txt: Out,
    imu_csv: Out,
    truth_nav: Out,
    truth_csv: Out,
    gnss_txt: Option<(Out, Out)>,
    baro_csv: Option<Out>,
    line: Line,
    /// Text buffers, one per formatting thread (reused from block to block).
    text: Vec<EpochText>,
}

impl FileSink {
    fn create(dir: &Path, gnss: bool, baro: bool) -> Result<Self> {
        let threads = std::thread::available_parallelism()
            .map_or(1, usize::from)
            .clamp(1, 8);
        let mut s = Self {
            imu_txt: Out::create(dir, "imu.txt")?,
            imu_csv: Out::create(dir, "imu.csv")?,
            truth_nav: Out::create(dir, "truth.nav")?,
            truth_csv: Out::create(dir, "truth.csv")?,
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
            text: (0..threads).map(|_| EpochText::default()).collect(),
        };
        let header = |o: &mut Out, h: &str| {
            writeln!(o.w, "{h}").with_context(|| format!("cannot write {}", o.path.display()))
        };
        header(
            &mut s.imu_csv,
            "t,dtheta_x,dtheta_y,dtheta_z,dvel_x,dvel_y,dvel_z",
        )?;
        header(
            &mut s.truth_csv,
            "t,lat_deg,lon_deg,h_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,w_x,w_y,w_z,f_x,f_y,f_z",
        )?;
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

    /// Write the formatted text of the first `parts` buffers, in order.
    fn write_text(&mut self, parts: usize) -> std::io::Result<()> {
        for t in &self.text[..parts] {
            self.imu_txt.w.write_all(&t.imu_txt)?;
            self.imu_csv.w.write_all(&t.imu_csv)?;
            self.truth_nav.w.write_all(&t.truth_nav)?;
            self.truth_csv.w.write_all(&t.truth_csv)?;
        }
        Ok(())
    }

    fn finish(self) -> Result<()> {
        self.imu_txt.finish()?;
        self.imu_csv.finish()?;
        self.truth_nav.finish()?;
        self.truth_csv.finish()?;
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
        self.text[0].clear();
        self.text[0].push(&[ImuEpoch {
            exact: *exact,
            measured: *measured,
            truth: *truth,
            kin: *kin,
        }]);
        self.write_text(1)
    }

    /// The GNSS and barometer epochs (a few) as they come; the IMU epochs formatted
    /// in parallel chunks, then written in order: the same bytes as one at a time.
    fn block(&mut self, block: &SimBlock) -> std::io::Result<()> {
        for (_, fix) in &block.gnss {
            self.gnss(fix)?;
        }
        for (_, r) in &block.baro {
            self.baro(r)?;
        }
        let chunk = block.imu.len().div_ceil(self.text.len()).max(1);
        let mut parts = 0;
        std::thread::scope(|scope| {
            let mut jobs = block.imu.chunks(chunk).zip(self.text.iter_mut());
            // The first chunk on this thread, the others on their own.
            let first = jobs.next();
            for (epochs, text) in jobs {
                parts += 1;
                scope.spawn(move || {
                    text.clear();
                    text.push(epochs);
                });
            }
            if let Some((epochs, text)) = first {
                parts += 1;
                text.clear();
                text.push(epochs);
            }
        });
        self.write_text(parts)
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
