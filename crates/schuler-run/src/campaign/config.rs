//! A campaign's configuration: one TOML file holding a `schuler simulate` scenario
//! (its keys at the top level, the seed replaced run by run), the `[navigate]` table
//! with `schuler nav`'s options (each key is a flag without its dashes: `lever_arm =
//! [0.5, 0.0, -1.0]` is `--lever-arm=0.5,0,-1`; `[navigate.aiding]` and
//! `[navigate.alignment]` may group them as in nav's own config) and the
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
    /// `schuler nav`'s flags from `[navigate]`.
    pub nav_flags: Vec<String>,
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
        let mut nav_flags = Vec::new();
        if let Some(nav) = nav {
            let toml::Value::Table(t) = nav else {
                bail!("in {origin}: `navigate` must be a table of `schuler nav` options");
            };
            flags_of(&t, &mut nav_flags).with_context(|| format!("in {origin}: [navigate]"))?;
        }
        Ok(Self {
            scenario,
            nav_flags,
            streams,
            origin: origin.to_string(),
        })
    }

    /// The configuration with `flags` over `[navigate]`'s: a flag given in both is
    /// `flags`' alone.
    pub fn with_flags(mut self, flags: &[String]) -> Self {
        let name = |f: &str| f.split('=').next().unwrap_or(f).to_string();
        let given: Vec<String> = flags.iter().map(|f| name(f)).collect();
        self.nav_flags.retain(|f| !given.contains(&name(f)));
        self.nav_flags.extend_from_slice(flags);
        self
    }

    /// The configuration in the file `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = schuler_io::formats::read_config_text(path)?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Self::from_toml(&text, dir, &path.display().to_string())
    }
}

/// `schuler nav`'s flags of a table of options: `key = value` is `--key=value` (`_`
/// as `-`), an array's items joined by commas, `true` the bare flag, `false` nothing;
/// sub-tables (`aiding`, `alignment`) add theirs.
fn flags_of(table: &toml::Table, flags: &mut Vec<String>) -> Result<()> {
    for (key, value) in table {
        let flag = format!("--{}", key.replace('_', "-"));
        match value {
            toml::Value::Table(t) => flags_of(t, flags)?,
            toml::Value::Boolean(true) => flags.push(flag),
            toml::Value::Boolean(false) => {}
            toml::Value::Array(items) => {
                let items: Result<Vec<String>> = items.iter().map(|v| scalar(key, v)).collect();
                flags.push(format!("{flag}={}", items?.join(",")));
            }
            v => flags.push(format!("{flag}={}", scalar(key, v)?)),
        }
    }
    Ok(())
}

/// A number or a string as the flag's text (a float in its shortest exact form).
fn scalar(key: &str, v: &toml::Value) -> Result<String> {
    Ok(match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(x) => format!("{x:?}"),
        _ => bail!("`{key}`: a number, a string or an array of them expected, got {v}"),
    })
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
    fn the_navigate_table_becomes_nav_flags_and_the_rest_the_scenario() {
        let c = CampaignConfig::from_toml(TEXT, Path::new(""), "test").expect("valid");
        assert_eq!(c.scenario.seed, 3);
        assert!(c.streams.baro && c.streams.gnss && !c.streams.gnss_velocity);
        // toml's tables keep their keys sorted.
        assert_eq!(
            c.nav_flags,
            [
                "--baro-std=0.5 m",
                "--lever-arm=0.5,0,-1.0",
                "--nhc",
                "--imu-grade=tactical",
                "--output-rate=1.0"
            ]
        );
    }

    #[test]
    fn a_wrong_value_names_its_key() {
        let text = TEXT.replace("nhc = true", "nhc = { a = 1 }\nx = [{ a = 1 }]");
        let e = CampaignConfig::from_toml(&text, Path::new(""), "test").expect_err("refused");
        assert!(format!("{e:#}").contains("`x`"), "{e:#}");
    }

    #[test]
    fn given_flags_replace_the_tables() {
        let c = CampaignConfig::from_toml(TEXT, Path::new(""), "test").expect("valid");
        let c = c.with_flags(&["--imu-grade=navigation".into(), "--smooth".into()]);
        let grades: Vec<&String> = c.nav_flags.iter().filter(|f| f.contains("grade")).collect();
        assert_eq!(grades, ["--imu-grade=navigation"]);
        assert_eq!(c.nav_flags.last().map(String::as_str), Some("--smooth"));
    }
}
