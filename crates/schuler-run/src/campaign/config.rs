//! A campaign's configuration: one TOML file holding a `schuler simulate` scenario
//! (its keys at the top level, the seed replaced run by run), the `[navigate]` table
//! with `schuler nav`'s options (each key a flag's name with underscores: `lever_arm =
//! [0.5, 0.0, -1.0]` is `--lever-arm=0.5,0,-1`; `[navigate.aiding]` and
//! `[navigate.alignment]` may group them as in nav's own config), read as nav's
//! description ([`crate::nav::NavConfig::from_options`]), and the
//! `[campaign]` table saying which simulated streams the filter gets.

use anyhow::{Context, Result, bail};
use schuler::sim::run::ScenarioSpec;
use serde::Deserialize;
use std::path::Path;

/// Which simulated streams a run's filter is given (`[campaign]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Streams {
    /// The GNSS positions (when the scenario has a receiver).
    #[serde(default = "yes")]
    pub gnss: bool,
    /// The receiver's velocities with its positions.
    #[serde(default)]
    pub gnss_velocity: bool,
    /// The barometer's heights (when the scenario has one).
    #[serde(default)]
    pub baro: bool,
}

fn yes() -> bool {
    true
}

impl Default for Streams {
    fn default() -> Self {
        Self {
            gnss: true,
            gnss_velocity: false,
            baro: false,
        }
    }
}

/// A campaign's configuration, parsed.
#[derive(Debug, Clone)]
pub struct CampaignConfig {
    /// The scenario (its `seed` is replaced by each run's).
    pub scenario: ScenarioSpec,
    /// `schuler nav`'s options from `[navigate]`, flat (its sub-tables' keys beside
    /// its own).
    pub nav_options: toml::Table,
    /// The streams the filter is given.
    pub streams: Streams,
    /// What the configuration came from (its file), for messages.
    pub origin: String,
}

impl CampaignConfig {
    /// The configuration in `text`, with relative paths (`motion_csv`) taken from `dir`;
    /// `origin` names the text in errors.
    pub fn from_toml(text: &str, dir: &Path, origin: &str) -> Result<Self> {
        let table: toml::Table = toml::from_str(text).with_context(|| format!("in {origin}"))?;
        Self::from_table(table, dir, origin)
    }

    /// The configuration of the keys of `table` ([`CampaignConfig::from_toml`]).
    pub fn from_table(mut table: toml::Table, dir: &Path, origin: &str) -> Result<Self> {
        let nav = table.remove("navigate");
        let streams = match table.remove("campaign") {
            Some(v) => v
                .try_into()
                .with_context(|| format!("in {origin}: [campaign]"))?,
            None => Streams::default(),
        };
        let scenario: ScenarioSpec = toml::Value::Table(table)
            .try_into()
            .with_context(|| format!("in {origin}: the scenario"))?;
        let scenario = crate::scenario::with_motion_csv(scenario, dir)?;
        let mut nav_options = toml::Table::new();
        if let Some(nav) = nav {
            let toml::Value::Table(t) = nav else {
                bail!("in {origin}: `navigate` must be a table of `schuler nav` options");
            };
            flatten(t, &mut nav_options);
            // Refused here, before any run, naming the option.
            crate::nav::NavConfig::from_options(nav_options.clone())
                .with_context(|| format!("in {origin}: [navigate]"))?;
        }
        Ok(Self {
            scenario,
            nav_options,
            streams,
            origin: origin.to_string(),
        })
    }

    /// The configuration with `options` over `[navigate]`'s: an option given in both
    /// is `options`' alone.
    pub fn with_options(mut self, options: toml::Table) -> Self {
        self.nav_options.extend(options);
        self
    }

    /// The configuration in the file `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = schuler_io::formats::read_config_text(path)?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Self::from_toml(&text, dir, &path.display().to_string())
    }
}

/// The options of `table` into `out`, a sub-table's (`aiding`, `alignment`) beside
/// the table's own.
fn flatten(table: toml::Table, out: &mut toml::Table) {
    for (key, value) in table {
        match value {
            toml::Value::Table(t) => flatten(t, out),
            v => {
                out.insert(key, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"
seed = 3
[start]
position = ["45 deg", "7 deg", "200 m"]
attitude = ["0 deg", "0 deg", "10 deg"]
[[motion]]
type = "hold"
duration = "10 s"
[imu]
rate_hz = 100
preset = "tactical"
[campaign]
baro = true
[navigate]
output_rate = 1.0
imu_grade = "tactical"
[navigate.aiding]
lever_arm = [0.5, 0, -1.0]
nhc = true
smooth = false
baro_std = "0.5 m"
"#;

    #[test]
    fn the_navigate_table_becomes_nav_options_and_the_rest_the_scenario() {
        let c = CampaignConfig::from_toml(TEXT, Path::new(""), "test").expect("valid");
        assert_eq!(c.scenario.seed, 3);
        assert!(c.streams.baro && c.streams.gnss && !c.streams.gnss_velocity);
        let flat: toml::Table = "output_rate = 1.0\nimu_grade = 'tactical'\n\
             lever_arm = [0.5, 0, -1.0]\nnhc = true\nsmooth = false\nbaro_std = '0.5 m'"
            .parse()
            .expect("toml");
        assert_eq!(c.nav_options, flat);
    }

    #[test]
    fn given_options_replace_the_tables() {
        let c = CampaignConfig::from_toml(TEXT, Path::new(""), "test").expect("valid");
        let given: toml::Table = "imu_grade = 'navigation'\nsmooth = true"
            .parse()
            .expect("toml");
        let c = c.with_options(given);
        assert_eq!(c.nav_options["imu_grade"].as_str(), Some("navigation"));
        assert_eq!(c.nav_options["smooth"].as_bool(), Some(true));
        assert_eq!(c.nav_options.len(), 6);
    }
}
