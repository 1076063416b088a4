//! Keyword arguments as a run's description: the Python layer passes `init_pos=(45,
//! 7, 245)` as a dict of plain values (bool, int, float, str, lists of them), read
//! here into the application layer's option types by serde, under the names of the
//! CLI's flags with underscores, so names, defaults, units and checks are the CLI's
//! and a refusal names the keyword ([`schuler_run::flat_options`]).

use anyhow::Result;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use schuler_run::aided::AidingOptions;
use schuler_run::flat_options::{keys_of, partition, read_group, unknown_option};
use schuler_run::imu_input::ImuInputOptions;
use schuler_run::nav::NavConfig;

/// The keyword arguments `options` as a table of plain values (None left out).
pub fn table(options: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in options.iter() {
        let name: String = k.extract()?;
        if !v.is_none() {
            let value = plain(&name, &v)?;
            t.insert(name, value);
        }
    }
    Ok(t)
}

/// One keyword argument's value as TOML's: bool, int, float, str, or a list of them.
fn plain(name: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    Ok(if v.is_instance_of::<PyBool>() {
        toml::Value::Boolean(v.extract()?)
    } else if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("option `{name}`: {v} is out of range")))?;
        toml::Value::Integer(i)
    } else if v.is_instance_of::<PyFloat>() {
        toml::Value::Float(v.extract()?)
    } else if v.is_instance_of::<PyString>() {
        toml::Value::String(v.extract()?)
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v.extract()?;
        toml::Value::Array(
            items
                .iter()
                .map(|x| plain(name, x))
                .collect::<PyResult<_>>()?,
        )
    } else {
        let kind = v.get_type().name()?;
        return Err(PyTypeError::new_err(format!(
            "option `{name}`: cannot pass a {kind} as an option value"
        )));
    })
}

/// A navigation run described by `options` (nav's flags with underscores).
pub fn nav_description(options: toml::Table) -> Result<NavConfig> {
    NavConfig::from_options(options)
}

/// The IMU reader's options and time window (`start`, `end` [s]) from `options`.
pub fn imu_options(options: toml::Table) -> Result<schuler_io::formats::ImuReadOptions> {
    let keys = ImuInputOptions::keys();
    let window = ["start".to_owned(), "end".to_owned()];
    let (mut groups, rest) = partition(options, &[&keys, &window]);
    if let Some(k) = rest.keys().next() {
        return Err(unknown_option(k, &[keys.as_slice(), &window].concat()));
    }
    let window = groups.pop().unwrap_or_default();
    let time = |name: &str| -> Result<Option<f64>> {
        window
            .get(name)
            .map(|v| {
                v.as_float()
                    .or_else(|| v.as_integer().map(|i| i as f64))
                    .ok_or_else(|| anyhow::anyhow!("option `{name}`: a time in seconds, got {v}"))
            })
            .transpose()
    };
    let input: ImuInputOptions = read_group(groups.pop().unwrap_or_default())?;
    input.read_options(time("start")?, time("end")?)
}

/// The aiding options (`gnss` among them) from `options`.
pub fn aiding_options(options: toml::Table) -> Result<AidingOptions> {
    let keys = keys_of::<AidingOptions>();
    let (mut groups, rest) = partition(options, &[&keys]);
    if let Some(k) = rest.keys().next() {
        return Err(unknown_option(k, &keys));
    }
    read_group(groups.pop().unwrap_or_default())
}

/// Checks that every `--name[=value]` of `flags` is an option of `A` (the commands
/// whose Python functions still hand flags to clap: `channel`, `allan_fit`), so a
/// misspelt keyword is refused as [`nav_description`]'s are, with the nearest name.
pub fn check_flag_names<A: clap::Args>(flags: &[String]) -> Result<()> {
    let known = keys_of::<A>();
    for flag in flags {
        if let Some(name) = flag.strip_prefix("--") {
            let name = name.split('=').next().unwrap_or(name).replace('-', "_");
            if !known.contains(&name) {
                return Err(unknown_option(&name, &known));
            }
        }
    }
    Ok(())
}
