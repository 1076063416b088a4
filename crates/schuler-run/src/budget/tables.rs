//! The budget's tables: `sigma.csv` (standard deviations every second) and
//! `shares.csv` (each source's variance at the end of each GNSS outage and at the
//! end, with its fraction of the whole).

use super::{BudgetResult, Share};
use anyhow::{Context, Result};
use std::fmt::Write;
use std::path::Path;

/// `sigma.csv`: time, then position (m), velocity (m/s) and attitude (deg) standard
/// deviations north, east, down.
pub fn sigma_csv(r: &BudgetResult) -> String {
    let mut s = String::from(
        "t_s,pos_n_m,pos_e_m,pos_d_m,vel_n_mps,vel_e_mps,vel_d_mps,att_n_deg,att_e_deg,att_d_deg\n",
    );
    for row in &r.sigma {
        let [p, v, a] = row.std;
        let a = a.map(f64::to_degrees);
        let _ = writeln!(
            s,
            "{:.3},{:.6},{:.6},{:.6},{:.7},{:.7},{:.7},{:.8},{:.8},{:.8}",
            row.t, p.x, p.y, p.z, v.x, v.y, v.z, a.x, a.y, a.z
        );
    }
    s
}

/// `shares.csv`: one row per event and source (and one `total` row per event):
/// variances of horizontal and down position, horizontal velocity, tilt and heading,
/// and the source's fraction of the horizontal position variance.
pub fn shares_csv(r: &BudgetResult) -> String {
    let mut s = String::from(
        "event,t_s,source,pos_h_var_m2,pos_h_fraction,pos_d_var_m2,vel_h_var_m2ps2,\
         tilt_var_deg2,heading_var_deg2\n",
    );
    let deg2 = 180.0 * 180.0 / (std::f64::consts::PI * std::f64::consts::PI);
    for e in &r.shares {
        let rows = r.sources.iter().map(String::as_str).zip(&e.parts);
        for (name, x) in rows.chain([("total", &e.total)]) {
            let fraction = if e.total.pos_h > 0.0 {
                x.pos_h / e.total.pos_h
            } else {
                0.0
            };
            let Share {
                pos_h,
                pos_d,
                vel_h,
                tilt,
                heading,
            } = *x;
            let _ = writeln!(
                s,
                "{},{:.3},{name},{pos_h:.6e},{fraction:.6},{pos_d:.6e},{vel_h:.6e},{:.6e},{:.6e}",
                e.event,
                e.t,
                tilt * deg2,
                heading * deg2,
            );
        }
    }
    s
}

/// Writes both tables into `dir` (created if missing).
pub fn write(dir: &Path, r: &BudgetResult) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, text) in [("sigma.csv", sigma_csv(r)), ("shares.csv", shares_csv(r))] {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
