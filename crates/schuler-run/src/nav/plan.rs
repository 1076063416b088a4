//! A navigation run's plan: the flags merged over the configuration file and every
//! value checked, with the message naming the flag.

use super::args::{InitChoice, NavArgs, NavConfig, load_config};
use crate::aided::{Aiding, AidingOptions, GivenReadings};
use crate::alignment::AlignOptions;
use crate::bag_input::BagArgs;
use crate::imu_input::ImuInputOptions;
use crate::log_input::LogArgs;
use crate::navigate::NavSettings;
use crate::options::{GradeChoice, Triple, rate};
use anyhow::{Context, Result, anyhow, bail};
use nalgebra::Vector3;
use schuler::earth::Geodetic;
use schuler::rotation::Euler;
use schuler::session::MechanizationConfig;
use schuler_io::formats::ImuReadOptions;
use std::path::{Path, PathBuf};

/// The rate of the navigation output [Hz]: positive, at most the fastest IMU's.
const OUTPUT_RATE: schuler::domain::Domain = schuler::domain::Domain {
    quantity: "output rate",
    min: f64::MIN_POSITIVE,
    ..schuler::domain::IMU_RATE
};

/// The mechanization options of flags over config, checked.
fn mechanization_config(args: &NavArgs, cfg: &NavConfig) -> Result<MechanizationConfig> {
    let choice = args.mechanization.or(cfg.mechanization).unwrap_or_default();
    let lat = args
        .auto_latitude
        .or(cfg.auto_latitude)
        .unwrap_or(MechanizationConfig::AUTO_LATITUDE_DEG);
    if !(lat.is_finite() && lat > 0.0 && lat < 90.0) {
        bail!("--auto-latitude must be between 0 and 90 deg (exclusive), got {lat}");
    }
    let hysteresis = args
        .auto_hysteresis
        .or(cfg.auto_hysteresis)
        .unwrap_or(MechanizationConfig::HYSTERESIS_DEG);
    if !(hysteresis.is_finite() && hysteresis >= 0.0 && hysteresis < lat) {
        bail!(
            "--auto-hysteresis must be at least 0 and below --auto-latitude ({lat} deg), \
             got {hysteresis}"
        );
    }
    Ok(MechanizationConfig {
        choice: choice.session(),
        auto_latitude: lat.to_radians(),
        hysteresis: hysteresis.to_radians(),
    })
}

/// A parsed `nav` command line: settings, the optional alignment and the aiding
/// options (not yet resolved).
#[derive(Debug, Clone)]
pub struct NavPlan {
    /// The run's settings.
    pub settings: NavSettings,
    /// Whether to align first (`--align`).
    pub align: bool,
    /// How the run starts.
    pub init: InitChoice,
    /// The alignment options (`--imu-grade` among them serves the filter too).
    pub alignment: AlignOptions,
    /// The aiding options.
    pub aiding: AidingOptions,
    /// Whether the IMU's axes were given (`--imu-axes`, `--imu-rotation`): a bag's
    /// IMU is FLU otherwise.
    pub axes_given: bool,
    /// The bag flags over the configuration's bag keys.
    pub bag: BagArgs,
    /// The device-log flags over the configuration's keys (a bag given as `--log`
    /// is in [`NavPlan::bag`] too).
    pub log: LogArgs,
}

/// The initial position of flags over config, checked.
fn init_pos(args: &NavArgs, cfg: &NavConfig) -> Result<Geodetic> {
    let Triple([lat, lon, h]) = args.init_pos.or(cfg.init_pos).context(
        "no initial position: give --init-pos LAT,LON,H (deg, deg, m), or --init gnss \
             to start in motion from the GNSS fixes (--gnss) or raw observations (--gnss-obs)",
    )?;
    schuler_io::formats::gnss::position_in_domain(lat, lon, h)
        .map_err(|(_, e)| anyhow!("--init-pos: {e}"))
}

/// The initial attitude of flags over config (zero when aligning), checked.
fn init_att(args: &NavArgs, cfg: &NavConfig, align_on: bool) -> Result<Euler> {
    let Triple([roll, pitch, yaw]) = match (args.init_att.or(cfg.init_att), align_on) {
        (Some(a), _) => a,
        (None, true) => Triple([0.0; 3]),
        (None, false) => bail!(
            "no initial attitude: give --init-att ROLL,PITCH,YAW (deg), or --align to \
             align at rest first; free-inertial navigation cannot start without one"
        ),
    };
    if !(-90.0..=90.0).contains(&pitch) {
        bail!("--init-att: pitch {pitch} deg is outside [-90, 90]");
    }
    Ok(Euler::from_degrees(roll, pitch, yaw))
}

/// The IMU reader's options of flags over config, checked.
fn read_options(args: &NavArgs, cfg: &NavConfig) -> Result<ImuReadOptions> {
    let (start, end) = (args.start.or(cfg.start), args.end.or(cfg.end));
    if let (Some(s), Some(e)) = (start, end)
        && s >= e
    {
        bail!("--start {s} is not before --end {e}");
    }
    args.input
        .clone()
        .or(cfg.input.clone())
        .read_options(start, end)
}

/// Merge flags over the config file and check every value (see [`NavPlan`]).
pub fn parse_nav_args(args: NavArgs) -> Result<NavPlan> {
    // A value may come from the configuration file: its errors name it.
    match args.config.clone() {
        Some(config) => load_config(&config)
            .and_then(|cfg| plan(args, cfg))
            .with_context(|| format!("with --config {}", config.display())),
        None => plan(args, NavConfig::default()),
    }
}

/// The plan of a run described as data alone ([`NavConfig::from_options`]: Python's
/// keyword arguments), every value checked as [`parse_nav_args`] checks flags.
pub fn plan_of(description: NavConfig) -> Result<NavPlan> {
    plan(NavArgs::default(), description)
}

/// [`parse_nav_args`] itself: `args` over `cfg`.
fn plan(args: NavArgs, cfg: NavConfig) -> Result<NavPlan> {
    let align_on = args.align || cfg.align.unwrap_or(false);
    let init = args.init.or(cfg.init).unwrap_or_default();
    // In motion the fixes give the position and the course (or the bank) the attitude.
    let in_motion = init != InitChoice::Given;
    if in_motion && align_on {
        bail!("--init gnss starts in motion; --align starts at rest: give one of them");
    }
    let input = args.input.clone().or(cfg.input.clone());
    let axes_given = input.imu_axes.is_some() || input.imu_rotation.is_some();
    let mut bag = args.bag.clone().or(cfg.bag_args());
    let log = args.log.clone().or(cfg.log_args());
    if let Some(path) = &log.log {
        check_log_input(&input, &bag, args.imu.is_some() || cfg.imu.is_some())?;
        if schuler_io::logs::detect(path)?.is_bag() {
            bag.bag = Some(path.clone());
        }
    }
    if bag.bag.is_some() {
        check_bag_input(&input)?;
        if args.imu.is_some() || cfg.imu.is_some() {
            bail!("an IMU log and a bag are both given (--imu or `imu`, --bag or `bag`): give one");
        }
    }
    let settings = settings(&args, &cfg, (&bag, &log), in_motion, align_on)?;
    let alignment = args
        .alignment
        .clone()
        .or(cfg.alignment.clone().unwrap_or_default());
    let base = args
        .config
        .as_deref()
        .and_then(Path::parent)
        .unwrap_or(Path::new(""));
    let from_config = cfg.aiding.unwrap_or_default().relative_to(base);
    if args.config.is_some() {
        let files = [("imu", cfg.imu.as_deref()), ("bag", cfg.bag.as_deref())];
        let files = files.into_iter().filter_map(|(k, p)| Some((k, p?)));
        config_files_exist(files.chain(from_config.input_files()))?;
    }
    let aiding = args.aiding.or(from_config);
    Ok(NavPlan {
        settings,
        align: align_on,
        init,
        alignment,
        aiding,
        axes_given,
        bag,
        log,
    })
}

/// Every input file a configuration names can be opened: else the error names its
/// key (the caller adds the file), not only the path.
fn config_files_exist<'a>(files: impl Iterator<Item = (&'a str, &'a Path)>) -> Result<()> {
    for (key, path) in files {
        std::fs::metadata(path)
            .with_context(|| format!("`{key} = {:?}`: cannot open it", path.display()))?;
    }
    Ok(())
}

/// The run's settings of flags over config, checked (the IMU log or the bag, the
/// window, the start, the output, the Earth model and the mechanization).
fn settings(
    args: &NavArgs,
    cfg: &NavConfig,
    (bag, log): (&BagArgs, &LogArgs),
    in_motion: bool,
    align_on: bool,
) -> Result<NavSettings> {
    Ok(NavSettings {
        imu: args
            .imu
            .clone()
            .or(cfg.imu.clone())
            .or(bag.bag.clone())
            .or(log.log.clone())
            .context(
                "no IMU log: give --imu FILE (or `imu = \"FILE\"` in the config), --bag BAG or --log FILE",
            )?,
        read: read_options(args, cfg)?,
        init_pos: if in_motion {
            Geodetic::new(0.0, 0.0, 0.0)
        } else {
            init_pos(args, cfg)?
        },
        init_vel: Vector3::from(args.init_vel.or(cfg.init_vel).unwrap_or(Triple([0.0; 3])).0),
        init_att: init_att(args, cfg, align_on || in_motion)?,
        output_rate: rate(
            "output-rate",
            &OUTPUT_RATE,
            args.output_rate.or(cfg.output_rate),
        )?,
        out: args
            .out
            .clone()
            .or(cfg.out.clone())
            .unwrap_or_else(|| PathBuf::from(".")),
        earth: args
            .earth
            .or(cfg.earth)
            .unwrap_or_default()
            .with_gravity(args.gravity.or(cfg.gravity))
            .map_err(anyhow::Error::msg)?,
        week: args.week.or(cfg.week).unwrap_or(0),
        mechanization: mechanization_config(args, cfg)?,
        out_bag: bag
            .out_bag
            .clone()
            .map(|path| schuler_io::bag::output::OutBag {
                path,
                clock: Default::default(),
            }),
    })
}

/// The IMU input options that say how a text log is laid out have no meaning for a
/// bag (its messages say it): refused rather than ignored.
fn check_bag_input(input: &ImuInputOptions) -> Result<()> {
    match text_log_flag(input) {
        Some(flag) => bail!(
            "{flag} does not apply to --bag: sensor_msgs/Imu holds rates in rad/s and \
             m/s^2 with header stamps"
        ),
        None => Ok(()),
    }
}

/// The first flag given that describes a text IMU log's layout, units or clock.
fn text_log_flag(input: &ImuInputOptions) -> Option<&'static str> {
    [
        (input.imu_format.is_some(), "--imu-format"),
        (input.imu_layout.is_some(), "--imu-layout"),
        (input.imu_columns.is_some(), "--imu-columns"),
        (input.gyro_unit.is_some(), "--gyro-unit"),
        (input.accel_unit.is_some(), "--accel-unit"),
        (input.imu_time_unit.is_some(), "--imu-time-unit"),
        (input.imu_rate.is_some(), "--imu-rate"),
    ]
    .into_iter()
    .find_map(|(given, flag)| given.then_some(flag))
}

/// A device log (`--log`) with an IMU log or a bag beside it, or with flags that
/// describe a text IMU log: refused rather than ignored.
fn check_log_input(input: &ImuInputOptions, bag: &BagArgs, imu_given: bool) -> Result<()> {
    if imu_given || bag.bag.is_some() {
        bail!(
            "--log and an IMU log or a bag are both given (--imu, --bag or their keys): give one"
        );
    }
    match text_log_flag(input) {
        Some(flag) => bail!(
            "{flag} does not apply to --log: a device log's reader converts its units, \
             axes and clock itself"
        ),
        None => Ok(()),
    }
}

/// The filter's IMU grade: `--imu-grade`, else navigation grade for alignment
/// (gyrocompassing needs it) but tactical for the filter (`aided`): an optimistic
/// noise model makes the gate refuse good fixes, a pessimistic one only costs a
/// little accuracy.
fn grade(alignment: &AlignOptions, aided: bool) -> GradeChoice {
    alignment.imu_grade.unwrap_or(if aided {
        GradeChoice::Tactical
    } else {
        GradeChoice::Navigation
    })
}

/// The filter's IMU grade of a plan ([`grade`]).
pub fn filter_grade(plan: &NavPlan) -> GradeChoice {
    grade(&plan.alignment, plan.aiding.any())
}

/// The run's aiding, if any: the options resolved (files read, or the `given`
/// readings) with the noise model of `--imu-grade`.
pub fn resolve_aiding(
    alignment: &AlignOptions,
    aiding: &AidingOptions,
    given: GivenReadings,
) -> Result<Option<Aiding>> {
    let noise = grade(alignment, aiding.any() || given.any()).noise()?;
    aiding.resolve_with(noise, given)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::NavConfig;
    use clap::Parser;

    #[derive(Parser)]
    #[command(no_binary_name = true)]
    struct Flags {
        #[command(flatten)]
        args: NavArgs,
    }

    fn of_flags(flags: &[&str]) -> Result<NavPlan> {
        parse_nav_args(Flags::try_parse_from(flags)?.args)
    }

    fn of_options(toml: &str) -> Result<NavPlan> {
        plan_of(NavConfig::from_options(toml.parse()?)?)
    }

    #[test]
    fn options_by_name_plan_the_run_their_flags_plan() {
        let flags = [
            "--imu=IMU.txt",
            "--init-pos=45.07,7.68,245",
            "--init-att=0,0,10",
            "--output-rate=10",
            "--gyro-unit=deg/s",
            "--imu-grade=tactical",
            "--coarse=30 s",
            "--gnss=gnss.txt",
            "--lever-arm=0.5,0,-1",
            "--baro-std=0.5",
            "--nhc",
            "--smooth",
        ];
        let options = r#"
            imu = "IMU.txt"
            init_pos = [45.07, 7.68, 245]
            init_att = [0, 0, 10]
            output_rate = 10
            gyro_unit = "deg/s"
            imu_grade = "tactical"
            coarse = "30 s"
            gnss = "gnss.txt"
            lever_arm = [0.5, 0, -1]
            baro_std = 0.5
            nhc = true
            smooth = true
        "#;
        let (a, b) = (
            of_flags(&flags).expect("flags"),
            of_options(options).expect("options"),
        );
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }

    #[test]
    fn options_by_name_are_refused_naming_the_option() {
        let msg = |toml: &str| of_options(toml).unwrap_err().to_string();
        let e = msg("lever_arms = [1, 2, 3]");
        assert_eq!(e, "unknown option `lever_arms` (did you mean `lever_arm`?)");
        let e = msg("lever_arm = [1, 2]");
        assert!(e.starts_with("option `lever_arm`: invalid length 2"), "{e}");
        let e = msg("imu_grade = \"superb\"");
        assert!(
            e.starts_with("option `imu_grade`: unknown variant `superb`"),
            "{e}"
        );
        let e = msg("init = 3");
        assert!(e.starts_with("option `init`: "), "{e}");
        // The domain checks are the flags' own.
        let e = msg("imu = \"x\"\ninit_pos = [95, 0, 0]");
        assert!(e.contains("latitude"), "{e}");
    }
}
