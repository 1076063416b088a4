//! A simulation scenario read from its TOML file, with the gnss-ins-sim motion file it
//! names.

use anyhow::{Context, Result};
use schuler::sim::run::ScenarioSpec;
use std::path::Path;

/// Read and parse a scenario file, and the gnss-ins-sim motion file it names (a path
/// relative to the scenario's folder).
pub fn load_scenario(path: &Path) -> Result<ScenarioSpec> {
    let text = schuler_io::formats::read_config_text(path)?;
    let spec: ScenarioSpec =
        toml::from_str(&text).with_context(|| format!("in {}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    with_raw_nav(with_motion_csv(spec, dir)?, dir)
}

/// `spec` with the navigation file of its `[gnss.raw]` block (a path relative to
/// `dir`), if it names one, read.
pub fn with_raw_nav(mut spec: ScenarioSpec, dir: &Path) -> Result<ScenarioSpec> {
    let Some(raw) = spec.gnss.as_mut().and_then(|g| g.raw.as_mut()) else {
        return Ok(spec);
    };
    if let Some(nav) = &raw.nav {
        let path = dir.join(nav);
        let (_, klobuchar, store) = schuler_io::formats::rinex::nav::read_store(&path)
            .with_context(|| "gnss.raw.nav".to_string())?;
        raw.data = Some(schuler::sim::raw_gnss::spec::NavData {
            store,
            klobuchar,
            file: Some(path),
        });
    }
    Ok(spec)
}

/// `spec` with its `motion_csv` (a path relative to `dir`), if it names one, read.
pub fn with_motion_csv(mut spec: ScenarioSpec, dir: &Path) -> Result<ScenarioSpec> {
    if let Some(csv) = &spec.motion_csv {
        let csv_path = dir.join(csv);
        let text = String::from_utf8_lossy(&schuler_io::formats::read_lines_whole(&csv_path)?)
            .into_owned();
        let def = schuler::sim::gnss_ins_sim::parse(&text)
            .with_context(|| format!("in {}", csv_path.display()))?;
        spec.imported = Some(def);
    }
    Ok(spec)
}

/// Whether the scenario's receiver measures velocity (`gnss.velocity_std` given):
/// without, its fixes' velocity is the truth with a standard deviation of 0, not a
/// measurement, and `gnss.csv` has no velocity columns.
pub fn simulates_gnss_velocity(spec: &ScenarioSpec) -> bool {
    spec.gnss.as_ref().is_some_and(|g| g.velocity_std.is_some())
}
