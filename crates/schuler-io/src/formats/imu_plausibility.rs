//! The plausibility check of an IMU log's first samples: what a sensor on the Earth
//! can read, and, when the file fails, the reading that would pass.
//!
//! Over the reader's lookahead (up to 200 intervals, 0.2–2 s at 100 Hz–1 kHz), with
//! the columns read as declared (layout, units, column order, time unit):
//! - the median sample interval must not exceed [`MAX_SAMPLE_INTERVAL_S`];
//! - the median specific-force magnitude must lie within [`SPECIFIC_FORCE_BOUNDS_G`]
//!   always, and within [`STEADY_SPECIFIC_FORCE_G`] when the specific force is steady
//!   (its vectors scatter by less than [`STEADY_SPREAD`] of their mean);
//! - the median angular-rate magnitude must stay below [`MAX_ANGULAR_RATE_DEG_S`].
//!
//! A file that fails is read again under every combination of the usual mistakes:
//! gyro and accelerometer columns exchanged, rates taken for increments or the
//! reverse, the accelerometer in g or in m/s², the gyro in deg or rad (per second or
//! not), the time in ms, µs or ns. Of the combinations that pass, those that look at
//! rest come first ([`AT_REST_FACTOR`], but not with a gyro quieter than the Earth's
//! rate, [`QUIET_GYRO_DEG_S`]), then the fewest flags, then the specific force
//! nearest 1 g; the first is named in the error with the flags that read the file so.
//! At rest a gyro's deg/s cannot be told from rad/s, which the error then says.

use nalgebra::Vector3;

use super::imu_columns::{AccelUnit, GyroUnit, Plan, TimeUnit, spec_text};
use super::imu_log::{ImuLayout, STANDARD_GRAVITY, median};

/// Longest plausible median sample interval [s]: an IMU sampled more slowly than 1 Hz
/// cannot be navigated (the motion between samples is unknown), while times in ms,
/// µs or ns read as seconds give intervals of 1–10⁷ s at 100 Hz–1 kHz.
pub const MAX_SAMPLE_INTERVAL_S: f64 = 1.0;

/// Range [g₀] of the median specific-force magnitude whatever the motion: below
/// 0.3 g₀ only free fall and ballistic flight (a median over the first samples of a
/// log recorded in free fall is rare enough to be told with `--no-layout-check`);
/// above 50 g₀ only gun launches and crashes — no vehicle's median over its first
/// samples, and beyond the range of most accelerometers (±16 g₀ MEMS, ±30–50 g₀
/// tactical).
pub const SPECIFIC_FORCE_BOUNDS_G: (f64, f64) = (0.3, 50.0);

/// Range [g₀] of the median specific force when it is steady (see [`STEADY_SPREAD`]):
/// at rest it is 1 g₀ (the accelerometer bias and scale error of the poorest MEMS move
/// it by a few per cent); a vehicle in steady motion feels at most 1.4 g₀ (a car
/// cornering or braking at 1 g₀) to 3 g₀ (an aircraft in a 70° banked turn). Only
/// rockets and centrifuges hold more, steadily.
pub const STEADY_SPECIFIC_FORCE_G: (f64, f64) = (0.3, 3.0);

/// Relative scatter below which the specific force counts as steady: the RMS of the
/// vectors' deviations from their mean over the mean's magnitude. Sensor noise is
/// below 1 % (1 mg₀ to 10 mg₀ per sample), an idling engine's vibration a few per
/// cent; a scale error does not change it.
pub const STEADY_SPREAD: f64 = 0.1;

/// Largest plausible median angular-rate magnitude [deg/s]: above the range of
/// navigation gyros (±2000 deg/s for MEMS, ±400–1000 deg/s tactical); deg/s read as
/// rad/s reach it as soon as the vehicle turns at 52 deg/s.
pub const MAX_ANGULAR_RATE_DEG_S: f64 = 3000.0;

/// A fix whose specific force is steady and within this factor of 1 g looks at rest,
/// and is preferred (most logs start at rest): a wrong fix rarely lands so near 1 g by
/// chance, while the poorest accelerometer at rest reads within a few per cent of it.
pub const AT_REST_FACTOR: f64 = 1.1;

/// Below this median angular rate [deg/s] a reading that looks at rest is not offered
/// as a fix: a gyro at rest reads the Earth's rate, 15 deg/h = 0.0042 deg/s, plus its
/// bias; this is half of it. (Not a check of its own: a simulated perfect gyro on a
/// non-rotating Earth reads zero.)
pub const QUIET_GYRO_DEG_S: f64 = 0.002;

/// One lookahead interval: its length [s] and the gyro and accelerometer columns as
/// written (not yet scaled to SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reading {
    /// Interval in ticks of the declared time unit (seconds for `s`).
    pub dt: f64,
    /// The gyro columns.
    pub gyro: Vector3<f64>,
    /// The accelerometer columns.
    pub accel: Vector3<f64>,
}

/// Which sensor a failed check concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sensor {
    /// The time column.
    Time,
    /// The gyro columns.
    Gyro,
    /// The accelerometer columns.
    Accel,
}

/// A failed check: the sensor to blame and the message (without the lines).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Finding {
    /// The sensor whose columns failed first.
    pub sensor: Sensor,
    /// What failed, with the numbers, and the flags that probably fix it.
    pub message: String,
}

/// A way of reading the columns: exchanged or not, layout and units.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Interpretation {
    swap: bool,
    layout: ImuLayout,
    gyro: GyroUnit,
    accel: AccelUnit,
    time: TimeUnit,
}

/// The medians of one way of reading.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Medians {
    /// Median interval [s].
    dt: f64,
    /// Median specific force [g₀].
    f_g: f64,
    /// Median angular rate [deg/s].
    w_deg_s: f64,
    /// Whether the specific force is steady.
    steady: bool,
}

impl Interpretation {
    /// The medians of `readings` (intervals in ticks of the declared time unit) read
    /// this way.
    fn medians(&self, readings: &[Reading]) -> Medians {
        let time_scale = 1.0 / self.time.ticks_per_second() as f64;
        let n = readings.len();
        let (mut dts, mut fs, mut ws) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let mut f_vectors = Vec::with_capacity(n);
        for r in readings {
            let dt = r.dt * time_scale;
            let (g, a) = if self.swap {
                (r.accel, r.gyro)
            } else {
                (r.gyro, r.accel)
            };
            let per = match self.layout {
                ImuLayout::Rates => 1.0,
                ImuLayout::Increments => 1.0 / dt,
            };
            let f = a * (self.accel.to_si() * per);
            dts.push(dt);
            fs.push(f.norm() / STANDARD_GRAVITY);
            ws.push((g * (self.gyro.to_si() * per)).norm().to_degrees());
            f_vectors.push(f);
        }
        let mean = f_vectors.iter().sum::<Vector3<f64>>() / n.max(1) as f64;
        let scatter = (f_vectors
            .iter()
            .map(|f| (f - mean).norm_squared())
            .sum::<f64>()
            / n.max(1) as f64)
            .sqrt();
        Medians {
            dt: median(&mut dts).unwrap_or(f64::NAN),
            f_g: median(&mut fs).unwrap_or(f64::NAN),
            w_deg_s: median(&mut ws).unwrap_or(f64::NAN),
            steady: scatter < STEADY_SPREAD * mean.norm(),
        }
    }
}

impl Medians {
    /// The checks these medians fail, first the one to blame, with their numbers.
    fn failures(&self) -> Vec<(Sensor, String)> {
        let mut out = Vec::new();
        if self.dt > MAX_SAMPLE_INTERVAL_S {
            out.push((
                Sensor::Time,
                format!(
                    "their median sample interval is {} s (an IMU samples at {MAX_SAMPLE_INTERVAL_S} s or faster)",
                    sig(self.dt)
                ),
            ));
        }
        let (low, high) = SPECIFIC_FORCE_BOUNDS_G;
        let steady_high = STEADY_SPECIFIC_FORCE_G.1;
        let f = self.f_g;
        if f.is_nan() || f < low {
            out.push((
                Sensor::Accel,
                format!("their median specific force is {} g, below the {low} g anything but free fall feels", sig(f)),
            ));
        } else if f > high {
            out.push((
                Sensor::Accel,
                format!(
                    "their median specific force is {} g, above the {high} g of any vehicle",
                    sig(f)
                ),
            ));
        } else if self.steady && f > steady_high {
            out.push((
                Sensor::Accel,
                format!(
                    "their median specific force is {} g and steady (scatter below {:.0} %), above the {steady_high} g no vehicle sustains",
                    sig(f),
                    STEADY_SPREAD * 100.0
                ),
            ));
        }
        if self.w_deg_s.is_nan() || self.w_deg_s > MAX_ANGULAR_RATE_DEG_S {
            out.push((
                Sensor::Gyro,
                format!(
                    "their median angular rate is {} deg/s, above the {MAX_ANGULAR_RATE_DEG_S} deg/s of any navigation gyro",
                    sig(self.w_deg_s)
                ),
            ));
        }
        out
    }
}

/// The gyro units of a layout.
fn gyro_units(layout: ImuLayout) -> [GyroUnit; 2] {
    match layout {
        ImuLayout::Rates => [GyroUnit::RadPerSecond, GyroUnit::DegPerSecond],
        ImuLayout::Increments => [GyroUnit::Rad, GyroUnit::Deg],
    }
}

/// The accelerometer units of a layout.
fn accel_units(layout: ImuLayout) -> &'static [AccelUnit] {
    match layout {
        ImuLayout::Rates => &[AccelUnit::MetrePerSecond2, AccelUnit::G],
        ImuLayout::Increments => &[AccelUnit::MetrePerSecond],
    }
}

/// Every way of reading the columns that changes the declared one by the usual
/// mistakes (the declared first).
fn alternatives(declared: Interpretation) -> Vec<Interpretation> {
    let times: &[TimeUnit] = if declared.time == TimeUnit::S {
        &[TimeUnit::S, TimeUnit::Ms, TimeUnit::Us, TimeUnit::Ns]
    } else {
        &[declared.time]
    };
    let mut out = vec![declared];
    for swap in [false, true] {
        for layout in [declared.layout, other(declared.layout)] {
            for gyro in gyro_units(layout) {
                for &accel in accel_units(layout) {
                    for &time in times {
                        let r = Interpretation {
                            swap,
                            layout,
                            gyro,
                            accel,
                            time,
                        };
                        if r != declared {
                            out.push(r);
                        }
                    }
                }
            }
        }
    }
    out
}

/// The other layout.
fn other(layout: ImuLayout) -> ImuLayout {
    match layout {
        ImuLayout::Rates => ImuLayout::Increments,
        ImuLayout::Increments => ImuLayout::Rates,
    }
}

/// What reading `r` instead of `d` changes, as words and as flags; `names_say_layout`:
/// the column names fix the layout, so a new layout needs new names.
fn changes(
    r: &Interpretation,
    d: &Interpretation,
    plan: &Plan,
    trailing: bool,
) -> (Vec<String>, Vec<String>) {
    let (mut words, mut flags) = (Vec::new(), Vec::new());
    let relayout = r.layout != d.layout;
    if r.swap {
        words.push("the gyro and accelerometer columns exchanged".to_owned());
    }
    if relayout {
        words.push(format!("{}, not {}", r.layout, d.layout));
    }
    if r.swap || (relayout && plan.names_say_layout) {
        flags.push(format!(
            "--imu-columns {}",
            spec_text(&plan.slot_of_col, trailing, r.layout, r.swap)
        ));
    } else if relayout {
        flags.push(format!("--imu-layout {}", r.layout));
    }
    if r.gyro.to_si() != d.gyro.to_si() || (relayout && r.gyro != GyroUnit::si(r.layout)) {
        words.push(format!("the gyro in {}", r.gyro));
        flags.push(format!("--gyro-unit {}", r.gyro));
    }
    if r.accel.to_si() != d.accel.to_si() || (relayout && r.accel != AccelUnit::si(r.layout)) {
        words.push(format!("the accelerometer in {}", r.accel));
        flags.push(format!("--accel-unit {}", r.accel));
    }
    if r.time != d.time {
        words.push(format!("the time in {}", r.time));
        flags.push(format!("--imu-time-unit {}", r.time));
    }
    (words, flags)
}

/// A way of reading that passes, with what it changes.
struct Fix {
    /// Rank: at rest or not (0 first), number of flags, distance of the specific force
    /// from 1 g (|ln f|).
    rank: (u8, usize, f64),
    /// What it changes, in words.
    words: Vec<String>,
    /// The flags that read the file so.
    flags: Vec<String>,
    /// Its medians.
    medians: Medians,
    /// Its gyro unit and the other of its layout (that values at rest cannot tell).
    gyro: (GyroUnit, GyroUnit),
}

/// The way of reading `readings` that passes the checks and is likeliest: first those
/// that look at rest (steady specific force within [`AT_REST_FACTOR`] of 1 g), then
/// the fewest flags, then the specific force nearest 1 g. A way that looks at rest
/// with a gyro quieter than [`QUIET_GYRO_DEG_S`] explains nothing (increments scaled
/// ×20 at 200 Hz read as rates in g give 0.98 g, but the gyro 1/200 of the Earth's
/// rate).
fn best_fix(
    readings: &[Reading],
    declared: Interpretation,
    plan: &Plan,
    trailing: bool,
) -> Option<Fix> {
    alternatives(declared)
        .into_iter()
        .skip(1)
        .filter_map(|r| {
            let m = r.medians(readings);
            if !m.failures().is_empty() {
                return None;
            }
            let distance = m.f_g.ln().abs();
            let at_rest = m.steady && distance < AT_REST_FACTOR.ln();
            if at_rest && m.w_deg_s < QUIET_GYRO_DEG_S {
                return None;
            }
            let (words, flags) = changes(&r, &declared, plan, trailing);
            let [a, b] = gyro_units(r.layout);
            Some(Fix {
                rank: (u8::from(!at_rest), flags.len(), distance),
                words,
                flags,
                medians: m,
                gyro: (r.gyro, if r.gyro == a { b } else { a }),
            })
        })
        .min_by(|x, y| {
            (x.rank.0, x.rank.1)
                .cmp(&(y.rank.0, y.rank.1))
                .then(x.rank.2.total_cmp(&y.rank.2))
        })
}

/// A number with 4 significant digits, in plain or scientific notation.
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let magnitude = x.abs().log10().floor();
    if (-3.0..5.0).contains(&magnitude) {
        // 0 to 6 decimals.
        format!("{x:.*}", (3.0 - magnitude).max(0.0) as usize)
    } else {
        format!("{x:.3e}")
    }
}

/// The message of a fix found for the `problems` of the declared reading.
fn fix_message(fix: &Fix, declared_text: &str, problems: &str) -> String {
    let m = &fix.medians;
    let gyro_told = fix.flags.iter().any(|f| f.starts_with("--gyro-unit"));
    let gyro_note = if fix.rank.0 == 0 && fix.gyro.0.layout() == ImuLayout::Rates && !gyro_told {
        let (read, other) = fix.gyro;
        format!(
            "; at rest the gyro's unit cannot be told from its values ({} deg/s in {read}, {} deg/s in {other}): check it (--gyro-unit)",
            sig(m.w_deg_s),
            sig(m.w_deg_s * other.to_si() / read.to_si()),
        )
    } else {
        String::new()
    };
    format!(
        "look like {}: read as declared ({declared_text}) {problems}; read that way, their median specific force is {} g and angular rate {} deg/s (g = {STANDARD_GRAVITY} m/s^2); give {}{gyro_note}; or turn this check off (--no-layout-check)",
        fix.words.join(" and "),
        sig(m.f_g),
        sig(m.w_deg_s),
        fix.flags.join(" ")
    )
}

/// Checks `readings` read as `plan` says; `trailing`: the plan allows further columns
/// (for the `--imu-columns` a fix suggests). `Ok` if they pass.
pub(crate) fn check(readings: &[Reading], plan: &Plan, trailing: bool) -> Result<(), Finding> {
    let declared = Interpretation {
        swap: false,
        layout: plan.layout,
        gyro: plan.gyro,
        accel: plan.accel,
        time: plan.time,
    };
    let seen = declared.medians(readings);
    let failures = seen.failures();
    let Some(&(sensor, _)) = failures.first() else {
        return Ok(());
    };
    let problems: Vec<&str> = failures.iter().map(|(_, m)| m.as_str()).collect();
    let problems = problems.join(" and ");
    let declared_text = format!(
        "{}, gyro in {}, accelerometer in {}, time in {}",
        plan.layout, plan.gyro, plan.accel, plan.time
    );
    let message = match best_fix(readings, declared, plan, trailing) {
        Some(fix) => fix_message(&fix, &declared_text, &problems),
        None => format!(
            "fail the plausibility check: read as declared ({declared_text}) {problems}; no usual mistake explains it (a scale error? the specific force is {} times g): check --imu-columns, --imu-layout, --gyro-unit, --accel-unit, --imu-time-unit, or turn this check off (--no-layout-check)",
            sig(seen.f_g)
        ),
    };
    Err(Finding { sensor, message })
}

/// Degrees per radian, for the tests' hand computations.
#[cfg(test)]
const DEG: f64 = 180.0 / std::f64::consts::PI;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::imu_columns::{Declared, default_plan};

    #[test]
    fn four_significant_digits() {
        assert_eq!(sig(1.00041), "1.000");
        assert_eq!(sig(20.0081), "20.01");
        assert_eq!(sig(11463.8), "11464");
        assert_eq!(sig(0.0375), "0.03750");
        assert_eq!(sig(5.0e6), "5.000e6");
        assert_eq!(sig(6.67e-5), "6.670e-5");
        assert_eq!(sig(0.0), "0");
    }

    /// `n` readings at rest at `hz`: gravity's reaction on −z, the Earth's rate and a
    /// small wobble, written in `layout` and the units of `plan`.
    fn at_rest(n: usize, hz: f64, plan: &Plan) -> Vec<Reading> {
        let dt = 1.0 / hz;
        (0..n)
            .map(|i| {
                let wob = 1e-3 * ((i % 7) as f64 - 3.0);
                let w = Vector3::new(5e-5, -4e-5, 3e-5 + wob * 1e-3);
                let f = Vector3::new(wob, -wob, -9.80);
                let per = if plan.layout == ImuLayout::Increments {
                    dt
                } else {
                    1.0
                };
                Reading {
                    dt: dt * plan.time.ticks_per_second() as f64,
                    gyro: w * per / plan.gyro.to_si(),
                    accel: f * per / plan.accel.to_si(),
                }
            })
            .collect()
    }

    fn plan(layout: Option<ImuLayout>, gyro: Option<GyroUnit>, accel: Option<AccelUnit>) -> Plan {
        default_plan(&Declared {
            layout,
            gyro,
            accel,
            time: None,
        })
        .expect("consistent")
    }

    #[test]
    fn good_files_pass() {
        for p in [
            plan(None, None, None),
            plan(Some(ImuLayout::Rates), None, None),
            plan(None, Some(GyroUnit::DegPerSecond), Some(AccelUnit::G)),
            plan(None, Some(GyroUnit::Deg), None),
        ] {
            assert_eq!(check(&at_rest(201, 200.0, &p), &p, false), Ok(()), "{p:?}");
        }
    }

    /// Written one way, read another: the error names the check and the fix.
    #[test]
    fn mistakes_are_named_with_their_flags() {
        let inc = plan(None, None, None);
        let rates = plan(Some(ImuLayout::Rates), None, None);
        let cases: [(Plan, Plan, Sensor, &str); 6] = [
            // Rates read as increments: 200 g.
            (
                rates.clone(),
                inc.clone(),
                Sensor::Accel,
                "look like rates, not increments",
            ),
            (
                inc.clone(),
                rates.clone(),
                Sensor::Accel,
                "--imu-layout increments",
            ),
            // g read as m/s^2: 0.102 g.
            (
                plan(Some(ImuLayout::Rates), None, Some(AccelUnit::G)),
                rates.clone(),
                Sensor::Accel,
                "--accel-unit g",
            ),
            // m/s^2 read as g: 9.8 g, steady.
            (
                rates.clone(),
                plan(None, None, Some(AccelUnit::G)),
                Sensor::Accel,
                "--accel-unit m/s^2",
            ),
            // Stamps in ns read as s.
            (
                {
                    let mut p = inc.clone();
                    p.time = TimeUnit::Ns;
                    p
                },
                inc.clone(),
                Sensor::Time,
                "--imu-time-unit ns",
            ),
            // Stamps in ms, rates in deg/s and g read as KF-GINS increments: at rest the
            // gyro's unit cannot be told (0.23 deg/s or 13 deg/s are both a MEMS bias),
            // the rest can.
            (
                {
                    let mut p = plan(None, Some(GyroUnit::DegPerSecond), Some(AccelUnit::G));
                    p.time = TimeUnit::Ms;
                    p
                },
                inc.clone(),
                Sensor::Time,
                "give --imu-layout rates --accel-unit g --imu-time-unit ms; at rest the gyro's unit cannot be told",
            ),
        ];
        for (written, read, sensor, fix) in cases {
            let e = check(&at_rest(201, 200.0, &written), &read, false).expect_err(fix);
            assert_eq!(e.sensor, sensor, "{}", e.message);
            assert!(e.message.contains(fix), "{fix}: {}", e.message);
        }
    }

    /// The rover: specific force before angular rate, rates, read as KF-GINS.
    #[test]
    fn swapped_columns_are_caught_at_rest_and_in_motion() {
        let rates = plan(Some(ImuLayout::Rates), None, None);
        let kf_gins = plan(None, None, None);
        let mut readings = at_rest(201, 200.0, &rates);
        for r in &mut readings {
            std::mem::swap(&mut r.gyro, &mut r.accel);
        }
        let e = check(&readings, &kf_gins, false).expect_err("swapped");
        assert!(
            e.message.contains("--imu-columns t,fx,fy,fz,wx,wy,wz"),
            "{}",
            e.message
        );
        // Turning at 0.05 rad/s the swapped gyro reads 1 g as increments at 200 Hz:
        // the angular rate check catches it (9.8 m/s^2 / dt as deg/s).
        for r in &mut readings {
            r.accel = Vector3::new(0.0, 0.03, 0.04);
        }
        let e = check(&readings, &kf_gins, false).expect_err("swapped, turning");
        assert_eq!(e.sensor, Sensor::Gyro, "{}", e.message);
        assert!(
            e.message.contains("--imu-columns t,fx,fy,fz,wx,wy,wz"),
            "{}",
            e.message
        );
        // Increments with swapped columns: named as increments.
        let mut readings = at_rest(201, 200.0, &kf_gins);
        for r in &mut readings {
            std::mem::swap(&mut r.gyro, &mut r.accel);
        }
        let e = check(&readings, &kf_gins, true).expect_err("swapped increments");
        assert!(
            e.message
                .contains("--imu-columns t,dvx,dvy,dvz,dtx,dty,dtz,..."),
            "{}",
            e.message
        );
    }

    /// Increments scaled by 5, 20 and 1000 are refused: steady above 3 g, or above 50 g.
    #[test]
    fn scaled_increments_are_refused() {
        let p = plan(None, None, None);
        for k in [5.0, 20.0, 1000.0] {
            let mut readings = at_rest(201, 200.0, &p);
            for r in &mut readings {
                r.accel *= k;
            }
            let e = check(&readings, &p, false).expect_err("scaled");
            assert_eq!(e.sensor, Sensor::Accel);
            let times = sig(9.80 / STANDARD_GRAVITY * k);
            assert!(
                e.message.contains(&format!("{times} times g")),
                "{k}: {}",
                e.message
            );
        }
        // Twice is within what a vehicle may feel: not caught.
        let mut readings = at_rest(201, 200.0, &p);
        for r in &mut readings {
            r.accel *= 2.0;
        }
        assert!(check(&readings, &p, false).is_ok());
    }

    /// deg/s read as rad/s: caught once the vehicle turns faster than 52 deg/s.
    #[test]
    fn degrees_read_as_radians_when_turning() {
        let rates = plan(Some(ImuLayout::Rates), None, None);
        let mut readings = at_rest(201, 200.0, &rates);
        for r in &mut readings {
            r.gyro = Vector3::new(0.0, 0.0, 60.0); // deg/s written
        }
        let e = check(&readings, &rates, false).expect_err("deg/s as rad/s");
        assert_eq!(e.sensor, Sensor::Gyro);
        assert!(
            e.message.contains(&format!("{} deg/s", sig(60.0 * DEG))),
            "{}",
            e.message
        );
        assert!(e.message.contains("--gyro-unit deg/s"), "{}", e.message);
    }
}
