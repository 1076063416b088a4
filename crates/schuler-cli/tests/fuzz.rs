//! Fuzz harnesses under stable `cargo test` (issue "Reliability"): every input parser,
//! and the mechanization with the filter, fed inputs no test author wrote.
//!
//! Each parser target mutates the seeds of its corpus (`tests/fuzz_corpus/<target>/`,
//! small excerpts of the repository's data and examples) with byte flips, extreme and
//! malformed numbers (`1e308`, `nan`, `-0`, `1,5`), separators, byte-order marks, cut,
//! duplicated and swapped lines, and checks what a user is promised: no panic; a
//! refusal names the file; an accepted input holds only finite values in their
//! physical domain. The session target pushes random but finite IMU samples and GNSS
//! fixes into a filter: no panic, and every epoch it reports is finite (or the session
//! stops with an error).
//!
//! Budget: [`DEFAULT_RUNS`] mutated inputs per target from a fixed seed, so `cargo
//! test` is reproducible and quick. `SCHULER_FUZZ_SECONDS=600` runs each target for
//! that long instead (and `SCHULER_FUZZ_SEED` moves the stream;
//! `SCHULER_FUZZ_TARGETS=imu,gnss` runs only the named parser targets, so a long campaign
//! can be split over processes); a failing input is saved in the temporary directory and
//! its path printed.

use nalgebra::Vector3;
use schuler::domain;
use schuler::earth::{Geodetic, Wgs84};
use schuler::filter::{GnssFix, ImuNoise, IntegrationConfig};
use schuler::imu::ImuSample;
use schuler::nav::NavState;
use schuler::rotation::Euler;
use schuler::session::{Aid, Epoch, FilterConfig, Session, SessionConfig, Start};
use schuler_io::formats::gnss::{GnssReadOptions, read_baro, read_gnss_log};
use schuler_io::formats::{ImuReadOptions, ImuReader, nav, nmea, rtklib, sensor_errors, vehicle};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Mutated inputs per target in a plain `cargo test`.
const DEFAULT_RUNS: u64 = 300;

/// SplitMix64: a small, fixed random stream (the same inputs on every machine).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Tokens a corrupt or foreign file holds where a number or separator should be.
const TOKENS: [&str; 30] = [
    "1e308",
    "-1e308",
    "1e20",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "-0",
    "1e-320",
    "0",
    "1e999",
    "9999999999999",
    "400",
    "-91",
    "1,5",
    "0x1F",
    "+",
    "-",
    ".",
    "e",
    "\u{feff}",
    "\r\n",
    ",",
    ";",
    " ",
    "\t",
    "\n",
    "#",
    "\"",
    "abc",
];

/// Bytes that change a line's structure.
const BYTES: [u8; 12] = [
    b'\n', b',', b';', b' ', b'\t', b'-', b'.', b'e', b'#', 0, 0xFF, b'"',
];

/// Spans of `text` that look like numbers: `[0-9.eE+-]` runs holding a digit.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let is = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-');
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        if is(text[i]) {
            let j = (i..text.len())
                .find(|&j| !is(text[j]))
                .unwrap_or(text.len());
            if text[i..j].iter().any(u8::is_ascii_digit) {
                spans.push((i, j));
            }
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// The line spans of `text` (each with its newline).
fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        spans.push((start, text.len()));
    }
    spans
}

/// One random edit of `t`.
fn mutate_once(rng: &mut Rng, t: &mut Vec<u8>, other: &[u8]) {
    let at = |rng: &mut Rng, t: &Vec<u8>| rng.below(t.len() + 1);
    match rng.below(10) {
        0 if !t.is_empty() => {
            let i = rng.below(t.len());
            t[i] ^= 1 << rng.below(8);
        }
        1 if !t.is_empty() => {
            let i = rng.below(t.len());
            t[i] = BYTES[rng.below(BYTES.len())];
        }
        2 => {
            let i = at(rng, t);
            let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
            t.splice(i..i, token.iter().copied());
        }
        3 => {
            let spans = numbers(t);
            if !spans.is_empty() {
                let (a, b) = spans[rng.below(spans.len())];
                let token = TOKENS[rng.below(13)].as_bytes();
                t.splice(a..b, token.iter().copied());
            }
        }
        4 if !t.is_empty() => {
            let a = rng.below(t.len());
            let b = (a + 1 + rng.below(16)).min(t.len());
            t.drain(a..b);
        }
        5 => {
            let l = lines(t);
            if !l.is_empty() {
                let (a, b) = l[rng.below(l.len())];
                let copy = t[a..b].to_vec();
                t.splice(b..b, copy);
            }
        }
        6 => {
            let l = lines(t);
            if l.len() > 1 {
                let (i, j) = (rng.below(l.len()), rng.below(l.len()));
                let (i, j) = (i.min(j), i.max(j));
                if i != j {
                    let (x, y) = (l[i], l[j]);
                    let mut out = t[..x.0].to_vec();
                    out.extend_from_slice(&t[y.0..y.1]);
                    out.extend_from_slice(&t[x.1..y.0]);
                    out.extend_from_slice(&t[x.0..x.1]);
                    out.extend_from_slice(&t[y.1..]);
                    *t = out;
                }
            }
        }
        7 => {
            let i = at(rng, t);
            t.truncate(i);
        }
        8 => {
            let l = lines(t);
            if !l.is_empty() {
                let (a, b) = l[rng.below(l.len())];
                t.drain(a..b);
            }
        }
        _ => {
            // A piece of another seed of the same target, spliced in.
            if !other.is_empty() {
                let a = rng.below(other.len());
                let b = (a + 1 + rng.below(256)).min(other.len());
                let i = at(rng, t);
                t.splice(i..i, other[a..b].iter().copied());
            }
        }
    }
}

/// A parser target: the name of its corpus folder, the file name the input gets, and
/// the check of one input (`Ok(true)`: accepted, `Ok(false)`: refused by name, `Err`:
/// a broken promise).
struct Target {
    name: &'static str,
    file: &'static str,
    check: fn(&Path, &[u8]) -> Result<bool, String>,
}

/// The seeds of `target`'s corpus.
fn corpus(target: &str) -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    let seeds: Vec<Vec<u8>> = files
        .iter()
        .map(|f| std::fs::read(f).expect("seed"))
        .collect();
    assert!(!seeds.is_empty(), "{}: no seed", dir.display());
    seeds
}

/// A refusal must name the file it refuses.
fn names_file(path: &Path, message: &str) -> Result<(), String> {
    let name = path.file_name().expect("name").to_string_lossy();
    if message.contains(&*name) {
        Ok(())
    } else {
        Err(format!("the error does not name the file: {message}"))
    }
}

/// The result of a reader: `Ok` values are checked by `each` (then `true`), errors
/// must name the file (then `false`).
fn judged<T, E: std::fmt::Display>(
    path: &Path,
    result: Result<T, E>,
    each: impl FnOnce(T) -> Result<(), String>,
) -> Result<bool, String> {
    match result {
        Ok(v) => each(v).map(|()| true),
        Err(e) => names_file(path, &format!("{e:#}")).map(|()| false),
    }
}

/// `x` finite, else what it is.
fn finite(what: &str, xs: &[f64]) -> Result<(), String> {
    match xs.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(format!("{what} {x} accepted")),
        None => Ok(()),
    }
}

fn in_domain(d: &domain::Domain, x: f64) -> Result<(), String> {
    d.check(x).map(|_| ()).map_err(|e| format!("accepted: {e}"))
}

fn check_fix(f: &GnssFix) -> Result<(), String> {
    finite("time", &[f.t])?;
    in_domain(&domain::LATITUDE, f.pos.lat)?;
    in_domain(&domain::LONGITUDE_WRAPPED, f.pos.lon)?;
    in_domain(&domain::HEIGHT, f.pos.h)?;
    f.pos_std
        .iter()
        .try_for_each(|x| in_domain(&domain::POSITION_STD, *x))?;
    if let Some((v, s)) = &f.vel {
        v.iter().try_for_each(|x| in_domain(&domain::SPEED, *x))?;
        s.iter()
            .try_for_each(|x| in_domain(&domain::VELOCITY_STD, *x))?;
    }
    Ok(())
}

fn imu(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let opened = ImuReader::new(
        std::io::BufReader::new(bytes),
        path,
        &ImuReadOptions::default(),
    );
    judged(path, opened, |reader| {
        for s in reader {
            let accepted = judged(path, s, |s| {
                finite("IMU value", &[s.t, s.dt])?;
                finite("IMU increment", s.dtheta.as_slice())?;
                finite("IMU increment", s.dvel.as_slice())?;
                in_domain(&domain::IMU_INTERVAL, s.dt)?;
                if s.dt > 0.0 {
                    Ok(())
                } else {
                    Err(format!("interval {} accepted", s.dt))
                }
            })?;
            if !accepted {
                // A refused sample ends the reading (with the error named).
                break;
            }
        }
        Ok(())
    })
}

fn gnss(path: &Path, _: &[u8]) -> Result<bool, String> {
    judged(
        path,
        read_gnss_log(path, &GnssReadOptions::default()),
        |log| log.fixes.iter().try_for_each(check_fix),
    )
}

fn nmea_log(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    // NMEA without GST gives no standard deviations: the user's --gnss-std.
    let opts = GnssReadOptions {
        default_std: Some(Vector3::new(1.0, 1.0, 2.0)),
        ..GnssReadOptions::default()
    };
    let log = nmea::read_nmea(path, bytes, &opts);
    judged(path, log, |log| log.fixes.iter().try_for_each(check_fix))
}

fn rtklib_log(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(bytes);
    let log = rtklib::read_rtklib(path, &text, &GnssReadOptions::default());
    judged(path, log, |log| log.fixes.iter().try_for_each(check_fix))
}

fn nav_log(path: &Path, _: &[u8]) -> Result<bool, String> {
    // Every column in its domain (issue 36: a height of 1.8e308 or a longitude of
    // 7680 deg was accepted); the seeds hold simulate's truth.csv (time named `t`).
    judged(path, nav::read_nav(path), |(_, rows)| {
        rows.iter().try_for_each(|r| {
            in_domain(&domain::TIME, r.t_sow)?;
            in_domain(&domain::LATITUDE, r.pos.lat)?;
            in_domain(&domain::LONGITUDE_WRAPPED, r.pos.lon)?;
            in_domain(&domain::HEIGHT, r.pos.h)?;
            r.v_n
                .iter()
                .try_for_each(|v| in_domain(&domain::SPEED, *v))?;
            finite("attitude", &[r.att.roll, r.att.pitch, r.att.yaw])
        })
    })
}

/// An accepted barometer CSV read its columns by unique names, every row as wide as
/// its header (issue 36: `t,t,h_m,outlier` and a header wider than its rows were read
/// from the wrong column).
fn baro_header_kept(bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text
        .lines()
        .map(|l| l.trim_start_matches('\u{feff}').trim())
        .filter(|l| !l.is_empty() && !l.starts_with('#') && !l.starts_with('%'));
    let Some(header) = lines.next() else {
        return Ok(());
    };
    let first = header.split([',', ';', ' ', '\t']).next().unwrap_or("");
    if first.parse::<f64>().is_ok() {
        return Ok(());
    }
    let names: Vec<String> = header.split(',').map(|n| n.trim().to_lowercase()).collect();
    for group in [
        &["t", "time", "timestamp"][..],
        &["h_m", "h", "height", "height_m", "alt", "altitude"],
    ] {
        if names.iter().filter(|n| group.contains(&n.as_str())).count() > 1 {
            return Err(format!("accepted a header naming a column twice: {header}"));
        }
    }
    match lines.find(|l| header.contains(',') && l.split(',').count() != names.len()) {
        Some(row) => Err(format!(
            "accepted a row of another width than `{header}`: {row}"
        )),
        None => Ok(()),
    }
}

fn baro(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    judged(path, read_baro(path), |rows| {
        baro_header_kept(bytes)?;
        rows.iter().try_for_each(|(t, h)| {
            finite("time", &[*t])?;
            in_domain(&domain::HEIGHT, *h)
        })
    })
}

fn odometer(path: &Path, _: &[u8]) -> Result<bool, String> {
    judged(path, vehicle::read_odometer(path), |rows| {
        rows.iter().try_for_each(|(t, v)| {
            finite("time", &[*t])?;
            in_domain(&domain::SPEED, *v)
        })
    })
}

fn heading(path: &Path, _: &[u8]) -> Result<bool, String> {
    judged(path, vehicle::read_heading(path), |rows| {
        rows.iter().try_for_each(|r| {
            finite("time", &[r.t])?;
            in_domain(&domain::HEADING, r.heading)?;
            in_domain(&domain::ANGLE_STD, r.heading_std)?;
            r.pitch.map_or(Ok(()), |(p, s)| {
                in_domain(&domain::PITCH, p)?;
                in_domain(&domain::ANGLE_STD, s)
            })
        })
    })
}

fn rest(path: &Path, _: &[u8]) -> Result<bool, String> {
    judged(path, vehicle::read_rest_intervals(path), |rows| {
        rows.iter().try_for_each(|(a, b)| {
            finite("rest", &[*a, *b])?;
            if b > a {
                Ok(())
            } else {
                Err(format!("rest [{a}, {b}] accepted"))
            }
        })
    })
}

fn sensor_errors_log(path: &Path, _: &[u8]) -> Result<bool, String> {
    judged(path, sensor_errors::read_sensor_errors(path), |rows| {
        rows.iter().try_for_each(|(t, e)| {
            finite("time", &[*t])?;
            finite("gyro bias", e.gyro_bias.as_slice())?;
            finite("accelerometer bias", e.accel_bias.as_slice())
        })
    })
}

fn scenario(path: &Path, _: &[u8]) -> Result<bool, String> {
    let spec = schuler_run::scenario::load_scenario(path);
    judged(path, spec, |spec| {
        // The models and the motion must build or be refused, never panic; a
        // refusal here comes from the library and names the key.
        // A model that builds has its sensor's rate in its domain (issue 36: a rate of
        // 1e6 or 1e308 Hz grew memory without bound).
        if spec.imu.model().is_ok() {
            in_domain(&domain::IMU_RATE, spec.imu.rate_hz)?;
        }
        if let Some(g) = spec.gnss.as_ref().filter(|g| g.model().is_ok()) {
            in_domain(&domain::GNSS_RATE, g.rate_hz)?;
        }
        if let Some(b) = spec.baro.as_ref().filter(|b| b.model().is_ok()) {
            in_domain(&domain::AID_RATE, b.rate_hz)?;
        }
        if let Ok(traj) = spec.trajectory(Wgs84) {
            let (t0, t1) = (traj.0.start(), traj.0.end());
            finite("trajectory span", &[t0, t1])?;
        }
        Ok(())
    })
}

fn nav_config(path: &Path, _: &[u8]) -> Result<bool, String> {
    // The files the seed names, beside the input: a configuration's paths must open
    // (issue 36: an error then names the key), the files themselves are not read here.
    let dir = path.parent().expect("folder").join("drive");
    std::fs::create_dir_all(&dir).expect("create drive/");
    for name in [
        "imu.txt",
        "gnss.txt",
        "baro.csv",
        "odometer.txt",
        "rest.txt",
    ] {
        std::fs::write(dir.join(name), "").expect("write a named file");
    }
    let args = schuler_run::nav::NavArgs {
        config: Some(path.to_path_buf()),
        ..Default::default()
    };
    // An accepted configuration is checked again by the session when it opens.
    judged(path, schuler_run::nav::parse_nav_args(args), |_| Ok(()))
}

/// The KF-GINS configuration, its `@DIR@` made the input's folder, where the GNSS seed
/// is written for it to read (the IMU log is opened only by the run).
fn kf_gins(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let dir = path.parent().expect("folder");
    let gnss = corpus("gnss");
    std::fs::write(dir.join("GNSS.txt"), &gnss[1]).expect("write GNSS.txt");
    let text = String::from_utf8_lossy(bytes).replace("@DIR@", &dir.to_string_lossy());
    std::fs::write(path, text).expect("write the configuration");
    let run = schuler_run::kf_gins::load(path, &Default::default());
    judged(path, run, |_| Ok(()))
}

/// Every parser target.
const TARGETS: [Target; 13] = [
    Target {
        name: "imu",
        file: "IMU.txt",
        check: imu,
    },
    Target {
        name: "gnss",
        file: "GNSS.txt",
        check: gnss,
    },
    Target {
        name: "nmea",
        file: "gnss.nmea",
        check: nmea_log,
    },
    Target {
        name: "rtklib",
        file: "solution.pos",
        check: rtklib_log,
    },
    Target {
        name: "nav",
        file: "nav.txt",
        check: nav_log,
    },
    Target {
        name: "baro",
        file: "baro.csv",
        check: baro,
    },
    Target {
        name: "odometer",
        file: "odometer.txt",
        check: odometer,
    },
    Target {
        name: "heading",
        file: "heading.txt",
        check: heading,
    },
    Target {
        name: "rest",
        file: "rest.txt",
        check: rest,
    },
    Target {
        name: "sensor_errors",
        file: "imu_err.txt",
        check: sensor_errors_log,
    },
    Target {
        name: "scenario",
        file: "scenario.toml",
        check: scenario,
    },
    Target {
        name: "nav_config",
        file: "nav.toml",
        check: nav_config,
    },
    Target {
        name: "kf_gins",
        file: "kf_gins.yaml",
        check: kf_gins,
    },
];

/// How long or how many inputs each target gets, and the stream's seed.
fn budget() -> (Option<Duration>, u64) {
    let seconds = std::env::var("SCHULER_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok());
    let seed = std::env::var("SCHULER_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5C_4C_E1);
    (seconds.map(Duration::from_secs_f64), seed)
}

/// Whether the run goes on after `runs` inputs started at `start`.
fn more(budget: Option<Duration>, start: Instant, runs: u64) -> bool {
    match budget {
        Some(d) => start.elapsed() < d,
        None => runs < DEFAULT_RUNS,
    }
}

/// Runs `target` on mutated seeds; the broken promises, each with the saved input.
fn fuzz(target: &Target, dir: &Path) -> Vec<String> {
    let seeds = corpus(target.name);
    let (limit, seed) = budget();
    let mut rng = Rng(seed
        ^ target
            .name
            .bytes()
            .fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(u64::from(b))));
    let path = dir.join(target.file);
    let (start, mut runs, mut accepted) = (Instant::now(), 0u64, 0u64);
    let mut failures = Vec::new();
    // The seeds themselves are valid inputs: accepted as they are.
    for (k, seed) in seeds.iter().enumerate() {
        std::fs::write(&path, seed).expect("write the seed");
        match (target.check)(&path, seed) {
            Ok(true) => {}
            other => failures.push(format!("{}: seed {k} not accepted: {other:?}", target.name)),
        }
    }
    while more(limit, start, runs) {
        let k = rng.below(seeds.len());
        let mut input = seeds[k].clone();
        let other = &seeds[rng.below(seeds.len())];
        for _ in 0..1 + rng.below(4) {
            mutate_once(&mut rng, &mut input, other);
        }
        std::fs::write(&path, &input).expect("write the input");
        let outcome = std::panic::catch_unwind(|| (target.check)(&path, &input));
        let why = match outcome {
            Ok(Ok(a)) => {
                accepted += u64::from(a);
                None
            }
            Ok(Err(e)) => Some(e),
            Err(_) => Some("panicked".to_owned()),
        };
        runs += 1;
        if let Some(why) = why {
            let saved = std::env::temp_dir().join(format!("schuler-fuzz-{}-{runs}", target.name));
            std::fs::write(&saved, &input).expect("save the input");
            failures.push(format!(
                "{}: {why} (input saved as {})",
                target.name,
                saved.display()
            ));
            if failures.len() >= 5 {
                break;
            }
        }
    }
    eprintln!(
        "fuzz {}: {runs} inputs in {:.1} s, {accepted} accepted, the others refused by name",
        target.name,
        start.elapsed().as_secs_f64()
    );
    failures
}

#[test]
fn parsers_keep_their_promises_on_mutated_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let chosen = std::env::var("SCHULER_FUZZ_TARGETS").ok();
    let wanted = |t: &&Target| {
        chosen
            .as_deref()
            .is_none_or(|list| list.split(',').any(|name| name.trim() == t.name))
    };
    let failures: Vec<String> = TARGETS
        .iter()
        .filter(wanted)
        .flat_map(|t| fuzz(t, dir.path()))
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A random value of magnitude up to `max`, spread over decades (most near zero, some
/// at the bound), of either sign.
fn spread(rng: &mut Rng, max: f64) -> f64 {
    let sign = if rng.below(2) == 0 { -1.0 } else { 1.0 };
    sign * max * 10f64.powf(-12.0 * rng.unit())
}

/// One session run: a random start, random finite IMU samples within the sensors'
/// domains and random GNSS fixes within theirs. `Err` when the session panics or
/// reports a non-finite epoch instead of an error.
fn session_run(rng: &mut Rng) -> Result<u64, String> {
    let lat = spread(rng, 89.9).to_radians();
    let start = NavState::new(
        0.0,
        Geodetic::new(lat, spread(rng, 180.0).to_radians(), spread(rng, 1e4)),
        Vector3::new(spread(rng, 300.0), spread(rng, 300.0), spread(rng, 50.0)),
        Euler::from_degrees(spread(rng, 180.0), spread(rng, 89.0), spread(rng, 180.0)),
    );
    let noise = ImuNoise::from_model(
        &schuler::sim::sensor_spec::ImuSpec::of_preset(
            100.0,
            schuler::sim::sensor_spec::Preset::Tactical,
        )
        .model()
        .map_err(|e| e.to_string())?,
    );
    let config = SessionConfig {
        output_rate: Some(10.0),
        filter: Some(FilterConfig::new(IntegrationConfig::new(noise))),
        ..SessionConfig::default()
    };
    let mut session =
        Session::new(Wgs84, config, Start::at(start)).map_err(|e| format!("start refused: {e}"))?;
    let (mut t, mut failed, mut pushed) = (0.0, false, 0u64);
    let check = |e: &Epoch| -> Result<(), String> {
        let s = &e.state;
        let q = s.q_bn.as_ref();
        finite(
            "epoch",
            &[s.t, s.pos.lat, s.pos.lon, s.pos.h, q.w, q.i, q.j, q.k],
        )?;
        finite("epoch velocity", s.v_n.as_slice())
    };
    for k in 0..400 {
        let dt = match rng.below(20) {
            0 => 10f64.powf(-9.0 * rng.unit()),
            1 => 60.0 * rng.unit().max(1e-6),
            _ => 0.01,
        };
        t += dt;
        let rate = domain::ANGULAR_RATE.max;
        let force = domain::SPECIFIC_FORCE.max;
        let sample = ImuSample {
            t,
            dt,
            dtheta: Vector3::new(spread(rng, rate), spread(rng, rate), spread(rng, rate)) * dt,
            dvel: Vector3::new(spread(rng, force), spread(rng, force), spread(rng, 9.8)) * dt,
        };
        if session.push_imu(sample).is_err() {
            // Driven out of the finite numbers, the session stops with an error.
            failed = true;
            break;
        }
        pushed += 1;
        if k % 50 == 49 {
            let fix = GnssFix {
                t,
                pos: Geodetic::new(
                    lat + spread(rng, 1e-3),
                    start.pos.lon + spread(rng, 1e-3),
                    spread(rng, 1e4),
                ),
                pos_std: Vector3::repeat(spread(rng, 1e3).abs().max(1e-3)),
                vel: None,
            };
            let _ = session.push(Aid::Gnss(fix));
        }
        for e in session.epochs() {
            check(&e)?;
        }
        let _ = session.events().count();
    }
    if !failed {
        session.end_of_input();
        for e in session.epochs() {
            check(&e)?;
        }
    }
    Ok(pushed)
}

#[test]
fn the_session_reports_finite_epochs_or_an_error_on_random_samples() {
    let (limit, seed) = budget();
    let mut rng = Rng(seed ^ 0x5E55_1011);
    let (start, mut runs, mut samples) = (Instant::now(), 0u64, 0u64);
    let mut failures = Vec::new();
    while more(limit, start, runs) {
        let state = rng.0;
        let outcome =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| session_run(&mut rng)));
        match outcome {
            Ok(Ok(n)) => samples += n,
            Ok(Err(e)) => failures.push(format!("stream state {state:#x}: {e}")),
            Err(_) => failures.push(format!("stream state {state:#x}: panicked")),
        }
        runs += 1;
        if failures.len() >= 5 {
            break;
        }
    }
    eprintln!(
        "fuzz session: {runs} runs, {samples} samples integrated, in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One start in motion on random fixes (issue 36: one fix, two, a log in reverse
/// order, repeated times panicked or gave NaN): a level IMU at rest or turning, then
/// 1 to 12 fixes along a random course, in time order, reversed or with a repeated
/// time, and the pair `(i, j)` the start is asked for as `motion_start` asks it
/// (`j` may equal `i` or lie past the last fix). `Err` on a panic or on a start
/// holding a non-finite value.
fn in_motion_run(rng: &mut Rng) -> Result<u64, String> {
    use schuler::align::in_motion::{InMotionConfig, course_pair, start_at_fix, start_in_motion};
    let turn = spread(rng, 0.5);
    let samples: Vec<ImuSample> = (1..=2000)
        .map(|k| ImuSample {
            t: f64::from(k) * 0.01,
            dt: 0.01,
            dtheta: Vector3::new(0.0, 0.0, turn * 0.01),
            dvel: Vector3::new(spread(rng, 1.0), spread(rng, 1.0), -9.8) * 0.01,
        })
        .collect();
    let n = 1 + rng.below(12);
    let (course, speed) = (spread(rng, std::f64::consts::PI), spread(rng, 50.0).abs());
    let std = spread(rng, 1e3).abs().max(1e-3);
    let mut fixes: Vec<GnssFix> = (0..n)
        .map(|k| {
            let t = 2.0 + k as f64;
            let d = speed * (t - 2.0);
            GnssFix {
                t,
                pos: Geodetic::new(
                    0.786 + d * course.cos() / 6.37e6,
                    0.134 + d * course.sin() / 4.5e6,
                    245.0 + spread(rng, 10.0),
                ),
                pos_std: Vector3::repeat(std),
                vel: None,
            }
        })
        .collect();
    match rng.below(4) {
        0 => fixes.reverse(),
        1 if n > 1 => fixes[n - 1].t = fixes[n - 2].t,
        _ => {}
    }
    let cfg = InMotionConfig::default();
    let (i, j) = (rng.below(n + 1), rng.below(n + 2));
    let starts = [
        start_in_motion(&Wgs84, &samples, &fixes, &cfg),
        start_at_fix(&Wgs84, &samples, &fixes, i, j, &cfg),
        course_pair(&Wgs84, &fixes, &cfg)
            .and_then(|(i, j)| start_at_fix(&Wgs84, &samples, &fixes, i, j, &cfg)),
    ];
    let mut made = 0;
    for s in starts.into_iter().flatten() {
        let p = &s.state;
        let q = p.q_bn.as_ref();
        finite(
            "start",
            &[
                p.t, p.pos.lat, p.pos.lon, p.pos.h, q.w, q.i, q.j, q.k, s.speed,
            ],
        )?;
        finite("start velocity", p.v_n.as_slice())?;
        for (what, v) in [
            ("pos_std", &s.pos_std),
            ("vel_std", &s.vel_std),
            ("att_std", &s.att_std),
        ] {
            if !v.iter().all(|x| x.is_finite() && *x > 0.0) {
                return Err(format!("{what} {v:?} of a start from {n} fixes"));
            }
        }
        made += 1;
    }
    Ok(made)
}

#[test]
fn in_motion_starts_are_finite_or_refused_on_random_fixes() {
    let (limit, seed) = budget();
    let mut rng = Rng(seed ^ 0x1A_0710);
    let (start, mut runs, mut made) = (Instant::now(), 0u64, 0u64);
    let mut failures = Vec::new();
    while more(limit, start, runs) {
        let state = rng.0;
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| in_motion_run(&mut rng))) {
            Ok(Ok(n)) => made += n,
            Ok(Err(e)) => failures.push(format!("stream state {state:#x}: {e}")),
            Err(_) => failures.push(format!("stream state {state:#x}: panicked")),
        }
        runs += 1;
        if failures.len() >= 5 {
            break;
        }
    }
    eprintln!(
        "fuzz in_motion: {runs} runs, {made} starts made, the others refused, in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One alignment of a log that turns at a random constant rate about a random axis
/// (issue 36: a log turning at 10 deg/s gave a confident wrong heading): 30 s coarse
/// and 60 s fine at 50 Hz, the navigation-grade noise model. No panic; an alignment
/// made is finite; a turn beyond 1 deg/s about a horizontal axis (the gyros tilt the
/// base by 90 deg while the accelerometers stay level: not a base at rest) is refused.
fn align_run(rng: &mut Rng) -> Result<bool, String> {
    use schuler::align::{AlignConfig, align};
    let axis = Vector3::new(spread(rng, 1.0), spread(rng, 1.0), spread(rng, 1.0));
    let axis = axis.try_normalize(1e-9).unwrap_or(Vector3::z());
    let rate = spread(rng, 20f64.to_radians()).abs();
    let w_earth = Vector3::new(5.2e-5, 0.0, -5.2e-5);
    let samples: Vec<ImuSample> = (1..=4500)
        .map(|k| ImuSample {
            t: f64::from(k) * 0.02,
            dt: 0.02,
            dtheta: (w_earth + axis * rate) * 0.02,
            dvel: Vector3::new(spread(rng, 1e-3), spread(rng, 1e-3), -9.8) * 0.02,
        })
        .collect();
    let noise = ImuNoise::from_model(
        &schuler::sim::sensor_spec::ImuSpec::of_preset(
            50.0,
            schuler::sim::sensor_spec::Preset::Navigation,
        )
        .model()
        .map_err(|e| e.to_string())?,
    );
    let cfg = AlignConfig {
        coarse: 30.0,
        fine: 60.0,
        max_heading_std: std::f64::consts::PI,
        ..AlignConfig::default()
    };
    let pos = Geodetic::new(45f64.to_radians(), 0.1, 100.0);
    let Ok(a) = align(Wgs84, pos, &samples, &noise, &cfg) else {
        return Ok(false);
    };
    let q = a.state.q_bn.as_ref();
    finite("aligned attitude", &[q.w, q.i, q.j, q.k])?;
    finite("attitude std", a.attitude_std.as_slice())?;
    let horizontal = (axis * rate).xy().norm();
    if horizontal > 1f64.to_radians() {
        return Err(format!(
            "aligned a base turning at {:.2} deg/s about a horizontal axis: yaw {:.2} ± {:.3} deg",
            horizontal.to_degrees(),
            a.state.euler().yaw.to_degrees(),
            a.attitude_std.z.to_degrees()
        ));
    }
    Ok(true)
}

#[test]
fn align_refuses_or_stays_finite_on_turning_logs() {
    let (limit, seed) = budget();
    let mut rng = Rng(seed ^ 0x000A_116E);
    let (start, mut runs, mut aligned) = (Instant::now(), 0u64, 0u64);
    let mut failures = Vec::new();
    // An alignment is costlier than a parse: a tenth of the parsers' inputs.
    while match limit {
        Some(d) => start.elapsed() < d,
        None => runs < DEFAULT_RUNS / 10,
    } {
        let state = rng.0;
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| align_run(&mut rng))) {
            Ok(Ok(a)) => aligned += u64::from(a),
            Ok(Err(e)) => failures.push(format!("stream state {state:#x}: {e}")),
            Err(_) => failures.push(format!("stream state {state:#x}: panicked")),
        }
        runs += 1;
        if failures.len() >= 5 {
            break;
        }
    }
    eprintln!(
        "fuzz align: {runs} turning logs, {aligned} aligned, the others refused, in {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
