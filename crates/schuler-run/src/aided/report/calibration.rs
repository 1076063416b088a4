//! The report's self-calibration section (`--estimate-lever-arm`,
//! `--estimate-gnss-time-offset`): each estimate over time with its ±3σ envelope and
//! the ±3σ the motion alone gives it ([`schuler::filter::calibration`]'s
//! `Excitation`), so that an estimate that stayed near its prior because nothing
//! excited it is seen as such; the final values in a table; `report/calibration.csv`.

use super::super::series::{Series, series};
use super::{Ctx, ReportSample, T_LABEL, envelope, f3, with_envelope};
use anyhow::Result;
use schuler::filter::CalibrationState;
use schuler_report::html::{Report, Table};
use schuler_report::plot::{LineStyle, Plot};

/// One calibrated quantity: a lever-arm axis or the time offset.
struct Quantity {
    name: &'static str,
    stem: &'static str,
    unit: &'static str,
    /// Display unit per SI unit.
    scale: f64,
    /// `[value, σ, σ from the motion alone, prior σ]` [SI], if estimated.
    pick: fn(&CalibrationState) -> Option<[f64; 4]>,
    /// Whether the motion observed it ([`schuler::filter::calibration::Estimate`]).
    observed: fn(&CalibrationState) -> bool,
}

fn lever(c: &CalibrationState, i: usize) -> Option<[f64; 4]> {
    c.lever_arm
        .map(|e| [e.value[i], e.std[i], e.excited_std[i], e.prior_std])
}

const QUANTITIES: [Quantity; 4] = [
    Quantity {
        name: "Lever arm, front",
        stem: "lever_arm_x",
        unit: "m",
        scale: 1.0,
        pick: |c| lever(c, 0),
        observed: |c| c.lever_arm.is_some_and(|e| e.observed()[0]),
    },
    Quantity {
        name: "Lever arm, right",
        stem: "lever_arm_y",
        unit: "m",
        scale: 1.0,
        pick: |c| lever(c, 1),
        observed: |c| c.lever_arm.is_some_and(|e| e.observed()[1]),
    },
    Quantity {
        name: "Lever arm, down",
        stem: "lever_arm_z",
        unit: "m",
        scale: 1.0,
        pick: |c| lever(c, 2),
        observed: |c| c.lever_arm.is_some_and(|e| e.observed()[2]),
    },
    Quantity {
        name: "GNSS time offset",
        stem: "gnss_time_offset",
        unit: "ms",
        scale: 1e3,
        pick: |c| {
            c.time_offset
                .map(|e| [e.value, e.std, e.excited_std, e.prior_std])
        },
        observed: |c| c.time_offset.is_some_and(|e| e.observed()),
    },
];

/// `q` of sample `x` in display units, NaN where not estimated.
fn of(q: &Quantity, x: &ReportSample) -> [f64; 4] {
    (q.pick)(&x.calibration).map_or([f64::NAN; 4], |v| v.map(|v| v * q.scale))
}

/// The estimate ± 3σ and ± 3σ from the motion alone (at most the prior's), GNSS gaps
/// shaded.
fn plot(c: &Ctx, q: &Quantity) -> Plot {
    let s: Series<3> = series(
        || {
            c.data.samples.iter().map(|x| {
                // The motion's σ is infinite until it shows anything: drawn up to
                // the prior's, which says as much.
                let [v, sd, motion, prior] = of(q, &x);
                (c.rel(x.t), [v, 3.0 * sd, 3.0 * motion.min(prior)])
            })
        },
        0,
    );
    let est = s.column(0);
    let (xb, yb) = envelope(&s.t, &est, &s.column(2));
    let mut plot = with_envelope(
        Plot::new(q.name, T_LABEL, &format!("{} [{}]", q.stem, q.unit)),
        ("estimate", "estimate ± 3σ"),
        &s.t,
        &est,
        &est,
        &s.column(1),
    )
    .line("± 3σ from the motion alone", &xb, &yb, LineStyle::Dotted);
    plot.height = 320;
    c.shade(plot)
}

/// The section, when the run calibrated anything.
pub(super) fn section(r: &mut Report, c: &Ctx) -> Result<()> {
    let Some(last) = c.data.samples.last() else {
        return Ok(());
    };
    let estimated: Vec<&Quantity> = QUANTITIES
        .iter()
        .filter(|q| (q.pick)(&last.calibration).is_some())
        .collect();
    if estimated.is_empty() {
        return Ok(());
    }
    let s = r.section("calibration", "Self-calibration");
    s.paragraph(
        "The antenna lever arm (body axes: front, right, down) and the GNSS time offset \
         (GNSS time + offset = IMU time, on top of --gnss-time-offset) as the filter \
         estimated them, sampled once a second, with the ±3σ of its covariance and the \
         ±3σ that the motion alone gives (what turns, rolls and speed changes showed, \
         without the priors; drawn at most as wide as the prior's): an estimate whose \
         envelope shrank while the motion's did not stayed near its prior because the \
         motion did not excite it.",
    );
    let mut table = Table::new([
        "quantity",
        "unit",
        "estimate",
        "σ",
        "σ from the motion alone",
        "prior σ",
        "observed",
    ]);
    for q in &estimated {
        let p = plot(c, q);
        let svg = c.svg(q.stem, &p)?;
        s.plot_with_files(&p, &[&svg, "report/calibration.csv"]);
        let [v, sd, motion, prior] = of(q, &last);
        table = table.row([
            q.name.to_owned(),
            q.unit.to_owned(),
            f3(v),
            f3(sd),
            f3(motion),
            f3(prior),
            if (q.observed)(&last.calibration) {
                "yes"
            } else {
                "no, near its prior"
            }
            .to_owned(),
        ]);
    }
    s.table(
        table.caption("Final estimates (observed: σ and the motion's σ both below half the prior)"),
    );
    let header = estimated.iter().fold(String::from("t"), |h, q| {
        format!("{h},{0}_{1},{0}_std_{1},{0}_motion_std_{1}", q.stem, q.unit)
    });
    c.csv(
        "calibration.csv",
        &header,
        c.data.samples.iter().map(|x| {
            let mut row = vec![Some(x.t)];
            for q in &estimated {
                let [v, sd, motion, _] = of(q, &x);
                row.extend([v, sd, motion].map(|v| Some(v).filter(|v| v.is_finite())));
            }
            row
        }),
    )?;
    Ok(())
}
