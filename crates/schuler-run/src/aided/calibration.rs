//! Self-calibration of an aided run: the flags that turn the lever-arm and
//! time-offset states on ([`schuler::filter::calibration`]), and what the run says of
//! them at its end: each estimate with its standard deviation, which ones the motion
//! did not observe (their values are the priors'), and the flags to give next time.

use super::AidingOptions;
use crate::options::quantity_in;
use anyhow::{Result, bail};
use nalgebra::Vector3;
use schuler::domain as d;
use schuler::filter::{Calibration, CalibrationState};
use schuler::units::Dimension;

/// The calibrations `--estimate-lever-arm`, `--estimate-gnss-time-offset` and
/// `--gnss-time-offset-walk` ask for.
pub fn calibration(o: &AidingOptions) -> Result<Calibration> {
    let prior = |flag: &str, v: &Option<String>, dim, domain| -> Result<Option<f64>> {
        match quantity_in(flag, v, dim, domain)? {
            Some(x) if x <= 0.0 => bail!("--{flag} must be a positive standard deviation"),
            x => Ok(x),
        }
    };
    let time_offset_std = prior(
        "estimate-gnss-time-offset",
        &o.estimate_gnss_time_offset,
        Dimension::Time,
        &d::GNSS_TIME_OFFSET,
    )?;
    let walk = o.gnss_time_offset_walk.unwrap_or(0.0);
    if !(walk.is_finite() && walk >= 0.0) {
        bail!("--gnss-time-offset-walk must be a finite density, not negative, got {walk}");
    }
    if walk > 0.0 && time_offset_std.is_none() {
        bail!(
            "--gnss-time-offset-walk drives the estimated offset: give --estimate-gnss-time-offset"
        );
    }
    Ok(Calibration {
        lever_arm_std: prior(
            "estimate-lever-arm",
            &o.estimate_lever_arm,
            Dimension::Length,
            &d::LEVER_ARM,
        )?,
        time_offset_std,
        time_offset_walk: walk,
    })
}

const AXES: [&str; 3] = ["front", "right", "down"];

/// What the run says of its calibrations at the end: `state` the filter's, `lever`
/// the lever arm given (`--lever-arm`), `shift` the time offset given
/// (`--gnss-time-offset`, added to the GNSS times as they were read). Empty without
/// calibration.
pub fn summary_lines(state: &CalibrationState, lever: &Vector3<f64>, shift: f64) -> Vec<String> {
    let mut lines = Vec::new();
    let mut unobserved = Vec::new();
    let mut flags = Vec::new();
    if let Some(l) = &state.lever_arm {
        let seen = l.observed();
        lines.push(format!(
            "lever arm estimated: {} m (front, right, down; prior ± {} m)",
            (0..3)
                .map(|i| format!("{:.3} ± {:.3}", l.value[i], l.std[i]))
                .collect::<Vec<_>>()
                .join(", "),
            l.prior_std
        ));
        for i in (0..3).filter(|&i| !seen[i]) {
            unobserved.push(format!("the lever arm's {} part", AXES[i]));
        }
        // What the motion did not observe stays as given.
        let next: Vec<String> = (0..3)
            .map(|i| format!("{:.3}", if seen[i] { l.value[i] } else { lever[i] }))
            .collect();
        flags.push(format!("--lever-arm {}", next.join(",")));
    }
    if let Some(t) = &state.time_offset {
        let total = shift + t.value;
        lines.push(format!(
            "GNSS time offset estimated: {:+.4} ± {:.4} s (GNSS time + offset = IMU time; prior ± {} s)",
            total, t.std, t.prior_std
        ));
        if t.observed() {
            flags.push(format!("--gnss-time-offset {total:.4}s"));
        } else {
            unobserved.push("the time offset".into());
        }
    }
    if !unobserved.is_empty() {
        lines.push(format!(
            "not observed: {}; the motion did not excite {} (a lever arm shows in turns and \
             leaning, a vertical one not on a level road; a time offset in speed changes and \
             turns, not at a constant velocity), so {} the prior's, not the data's",
            unobserved.join(", "),
            if unobserved.len() > 1 { "them" } else { "it" },
            if unobserved.len() > 1 {
                "their values are"
            } else {
                "its value is"
            }
        ));
    }
    if !flags.is_empty() {
        lines.push(format!("use next time: {}", flags.join(" ")));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use schuler::filter::Estimate;

    #[test]
    fn observed_estimates_become_flags_and_the_rest_is_named() {
        let state = CalibrationState {
            lever_arm: Some(Estimate {
                value: Vector3::new(0.79, -0.303, -0.6),
                std: Vector3::new(0.03, 0.02, 0.9),
                prior_std: 1.0,
                excited_std: Vector3::new(0.015, 0.015, 3.0),
            }),
            time_offset: Some(Estimate {
                value: 0.0773,
                std: 0.002,
                prior_std: 0.5,
                excited_std: 0.0012,
            }),
        };
        let lines = summary_lines(&state, &Vector3::new(0.5, 0.0, -1.0), -18.0);
        assert_eq!(
            lines[0],
            "lever arm estimated: 0.790 ± 0.030, -0.303 ± 0.020, -0.600 ± 0.900 m (front, right, down; prior ± 1 m)"
        );
        assert!(lines[1].starts_with("GNSS time offset estimated: -17.9227 ± 0.0020 s"));
        assert!(
            lines[2].starts_with(
                "not observed: the lever arm's down part; the motion did not excite it"
            )
        );
        assert_eq!(
            lines[3],
            "use next time: --lever-arm 0.790,-0.303,-1.000 --gnss-time-offset -17.9227s"
        );
        assert!(summary_lines(&CalibrationState::default(), &Vector3::zeros(), 0.0).is_empty());
    }
}
