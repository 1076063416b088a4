//! Options given flat, by name: Python's keyword arguments (`lever_arm=(0.5, 0, -1)`)
//! and a campaign's option tables. Each name is a flag's with underscores; it goes to
//! the option group that owns it and is read there by serde, alone first, so that an
//! error names the option and a misspelt name gets the nearest known one.

use anyhow::{Result, anyhow};
use serde::Deserialize as _;
use serde::de::DeserializeOwned;

/// The option names of a clap argument group: its flags' ids (with underscores).
pub fn keys_of<A: clap::Args>() -> Vec<String> {
    A::augment_args(clap::Command::new("keys"))
        .get_arguments()
        .map(|a| a.get_id().to_string())
        .collect()
}

/// An option name that no option group knows, with the nearest known name when one is
/// close (Jaro–Winkler similarity above 0.8, as clap suggests flags). The Python
/// package raises it as a `TypeError`, as Python does for an unexpected keyword.
#[derive(Debug, thiserror::Error)]
#[error("unknown option `{name}`{}", match .nearest { Some(k) => format!(" (did you mean `{k}`?)"), None => String::new() })]
pub struct UnknownOption {
    /// The name given.
    pub name: String,
    /// The nearest known name, if one is close.
    pub nearest: Option<String>,
}

/// The error for an option `name` that is none of `known` ([`UnknownOption`]).
pub fn unknown_option(name: &str, known: &[String]) -> anyhow::Error {
    let nearest = known
        .iter()
        .map(|k| (strsim::jaro_winkler(name, k), k))
        .filter(|(score, _)| *score > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, k)| k.clone());
    UnknownOption {
        name: name.to_owned(),
        nearest,
    }
    .into()
}

/// `options` split by `groups` (each a list of names): one table per group, in order,
/// then the names no group owns.
pub fn partition(options: toml::Table, groups: &[&[String]]) -> (Vec<toml::Table>, toml::Table) {
    let mut tables = vec![toml::Table::new(); groups.len()];
    let mut rest = toml::Table::new();
    for (k, v) in options {
        match groups.iter().position(|g| g.contains(&k)) {
            Some(i) => tables[i].insert(k, v),
            None => rest.insert(k, v),
        };
    }
    (tables, rest)
}

/// `table` read as `T`, each option alone first so that an error names it
/// (`option `lever_arm`: invalid length 2, expected an array of length 3`).
pub fn read_group<T: DeserializeOwned>(table: toml::Table) -> Result<T> {
    for (k, v) in &table {
        let one = toml::Table::from_iter([(k.clone(), v.clone())]);
        if let Err(e) = toml::Value::Table(one).try_into::<T>() {
            return Err(anyhow!("option `{k}`: {}", e.message().trim()));
        }
    }
    Ok(toml::Value::Table(table).try_into::<T>()?)
}

/// Serde's reader of an option written as text with an optional unit (`"0.5 m"`,
/// `"1 %"`) that also takes a bare number, meaning the option's default unit, as its
/// flag does (`--baro-std 0.5`).
pub fn text_or_number<'de, D>(d: D) -> Result<Option<String>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum TextOrNumber {
        Text(String),
        Integer(i64),
        Float(f64),
    }
    Ok(Option::<TextOrNumber>::deserialize(d)?.map(|v| match v {
        TextOrNumber::Text(s) => s,
        TextOrNumber::Integer(i) => i.to_string(),
        TextOrNumber::Float(x) => x.to_string(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(clap::Args, serde::Deserialize, Debug, Default)]
    #[serde(deny_unknown_fields)]
    struct Group {
        #[arg(long)]
        lever_arm: Option<crate::options::Triple>,
        #[arg(long)]
        #[serde(default, deserialize_with = "text_or_number")]
        baro_std: Option<String>,
    }

    fn table(text: &str) -> toml::Table {
        text.parse().expect("toml")
    }

    #[test]
    fn a_misspelt_option_gets_the_nearest_name() {
        let known = keys_of::<Group>();
        assert_eq!(known, ["lever_arm", "baro_std"]);
        let e = unknown_option("lever_arms", &known).to_string();
        assert_eq!(e, "unknown option `lever_arms` (did you mean `lever_arm`?)");
        let e = unknown_option("zzz", &known).to_string();
        assert_eq!(e, "unknown option `zzz`");
    }

    #[test]
    fn options_go_to_their_group_and_errors_name_them() {
        let known = keys_of::<Group>();
        let (groups, rest) = partition(table("lever_arm = [1, 2, 3]\nimu = 'x'"), &[&known]);
        assert_eq!(rest.len(), 1);
        let g: Group = read_group(groups[0].clone()).expect("group");
        assert_eq!(g.lever_arm.map(|t| t.0), Some([1.0, 2.0, 3.0]));
        let e = read_group::<Group>(table("baro_std = 1\nlever_arm = [1, 2]")).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("option `lever_arm`: invalid length 2"),
            "{e}"
        );
    }

    #[test]
    fn a_bare_number_is_a_quantity_in_its_default_unit() {
        for (text, want) in [
            ("0.5", "0.5"),
            ("2", "2"),
            ("'0.5 m'", "0.5 m"),
            ("1e-5", "0.00001"),
        ] {
            let g: Group = read_group(table(&format!("baro_std = {text}"))).expect("read");
            assert_eq!(g.baro_std.as_deref(), Some(want), "{text}");
        }
    }
}
