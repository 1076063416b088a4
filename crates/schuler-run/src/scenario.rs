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
    with_motion_csv(spec, path.parent().unwrap_or(Path::new("")))
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
