//! `montecarlo(...)`: the CLI's Monte-Carlo campaign ([`schuler_run::campaign`]) on a
//! campaign file or text, its table (one row per run, `runs.csv`'s columns) as a dict
//! of numpy arrays. The same function on a list of seeds serves `schuler.dask`, which
//! sends each seed to a worker of a cluster.

use crate::errors::IntoPy;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use schuler_run::campaign::{self, COLUMNS, CampaignConfig};
use std::path::{Path, PathBuf};

/// Where a campaign comes from: a file, or TOML or JSON text (relative paths from
/// `base`).
pub struct Source<'a> {
    path: Option<&'a Path>,
    text: Option<&'a str>,
    format: &'a str,
    base: Option<&'a Path>,
}

/// The campaign of `src`, with `options` over its `[navigate]` options (they win).
fn config(src: &Source<'_>, options: toml::Table) -> anyhow::Result<CampaignConfig> {
    let base = src.base.unwrap_or(Path::new(""));
    let c = match (src.path, src.text) {
        (Some(p), _) => CampaignConfig::load(p)?,
        (None, Some(t)) if src.format == "json" => {
            let table: toml::Table = serde_json::from_str(t)
                .map_err(|e| anyhow::anyhow!("in the campaign (dict): {e}"))?;
            CampaignConfig::from_table(table, base, "the campaign (dict)")?
        }
        (None, Some(t)) => CampaignConfig::from_toml(t, base, "the campaign (TOML text)")?,
        (None, None) => anyhow::bail!("no campaign: give a file or its text"),
    };
    let c = c.with_options(options);
    // A misspelt keyword is refused before any run.
    schuler_run::nav::NavConfig::from_options(c.nav_options.clone())?;
    Ok(c)
}

/// Runs the campaign of `path` (or `text` in `format` "toml" or "json", relative
/// paths from `base`) with `options` (nav's, by name)
/// over its `[navigate]` options, for the scenario seeds `seeds`, on `threads`
/// threads (None: one per core): a dict of the table's columns (`seed`, then
/// `runs.csv`'s), in the order of `seeds`. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (seeds, path=None, text=None, format="toml", base=None, options=None, threads=None))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments
pub fn montecarlo_seeds<'py>(
    py: Python<'py>,
    seeds: Vec<u64>,
    path: Option<PathBuf>,
    text: Option<String>,
    format: &str,
    base: Option<PathBuf>,
    options: Option<Bound<'py, PyDict>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    if threads == Some(0) {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "threads must be at least 1",
        ));
    }
    let src = Source {
        path: path.as_deref(),
        text: text.as_deref(),
        format,
        base: base.as_deref(),
    };
    let options = match &options {
        Some(o) => crate::options::table(o)?,
        None => toml::Table::new(),
    };
    let c = config(&src, options).py_err(py)?;
    let results = py
        .detach(|| campaign::run_seeds(&c, &seeds, threads))
        .py_err(py)?;
    let d = PyDict::new(py);
    let seed: Vec<u64> = results.iter().map(|r| r.row.seed).collect();
    d.set_item("seed", seed.into_pyarray(py))?;
    for (k, name) in COLUMNS.iter().enumerate() {
        let col: Vec<f64> = results.iter().map(|r| r.row.values[k]).collect();
        d.set_item(*name, col.into_pyarray(py))?;
    }
    Ok(d)
}
