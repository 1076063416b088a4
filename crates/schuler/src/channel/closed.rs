//! Closed-form responses of the error models to constant errors: the general solution
//! (18)/(19) of (13), its special cases (20)-(23), and the free vertical channel (32).
//!
//! For (13) with constant Δf and ν, ω0 = sqrt(g/a), c = cos ω0t, s = sin ω0t:
//!
//! ```text
//! ΔV = -gν/ω0² + (ΔV0 + gν/ω0²) c + (Δf - gα0) s / ω0                      (18)
//! α  = Δf/g + (ω0/g)(ΔV0 + gν/ω0²) s - (Δf - gα0) c / g                   (18)
//! Δr = Δr0 - (gν/ω0²) t + (ΔV0 + gν/ω0²) s / ω0 - (Δf - gα0)(c - 1)/ω0²   (19)
//! ```

use super::linear::{ErrorModel, ErrorState};

/// Constant errors driving (13): the inputs of the general solution (18)/(19).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ConstantErrors {
    /// Accelerometer error Δf on the model horizontal axis [m/s^2].
    pub accel_bias: f64,
    /// Drift ν in (13)'s sign convention (platform drift; minus the SINS gyro drift) [rad/s].
    pub drift: f64,
    /// Initial vertical error α0 \[rad\].
    pub alpha0: f64,
    /// Initial velocity error ΔV0 [m/s].
    pub dv0: f64,
    /// Initial position error Δr0 \[m\].
    pub dr0: f64,
}

/// General solution (18)/(19) of (13) for constant errors, at time `t` \[s\].
pub fn response(model: &ErrorModel, e: &ConstantErrors, t: f64) -> ErrorState {
    let g = model.g;
    let w0 = model.schuler_frequency();
    let (s, c) = (w0 * t).sin_cos();
    let drift_v = g * e.drift / (w0 * w0);
    let v_amp = e.dv0 + drift_v;
    let f_amp = e.accel_bias - g * e.alpha0;
    ErrorState {
        dr: e.dr0 - drift_v * t + v_amp * s / w0 - f_amp * (c - 1.0) / (w0 * w0),
        dv: -drift_v + v_amp * c + f_amp * s / w0,
        alpha: e.accel_bias / g + (w0 / g) * v_amp * s - f_amp * c / g,
    }
}

/// Accelerometer bias Δf alone (20): `Δr = Δf/ω0² (1 - c)`, `ΔV = Δf/ω0 s`, `α = Δf/g (1 - c)`.
pub fn accel_bias_response(model: &ErrorModel, accel_bias: f64, t: f64) -> ErrorState {
    let w0 = model.schuler_frequency();
    let (s, c) = (w0 * t).sin_cos();
    ErrorState {
        dr: accel_bias / (w0 * w0) * (1.0 - c),
        dv: accel_bias / w0 * s,
        alpha: accel_bias / model.g * (1.0 - c),
    }
}

/// Initial vertical error α0 alone (21): `Δr = gα0/ω0² (c - 1)`, `ΔV = -gα0/ω0 s`, `α = α0 c`.
pub fn initial_tilt_response(model: &ErrorModel, alpha0: f64, t: f64) -> ErrorState {
    let w0 = model.schuler_frequency();
    let (s, c) = (w0 * t).sin_cos();
    let g = model.g;
    ErrorState {
        dr: g * alpha0 / (w0 * w0) * (c - 1.0),
        dv: -g * alpha0 / w0 * s,
        alpha: alpha0 * c,
    }
}

/// Drift ν alone (22): `Δr = gν/ω0³ (s - ω0t)`, `ΔV = gν/ω0² (c - 1)`, `α = ν/ω0 s`.
pub fn drift_response(model: &ErrorModel, drift: f64, t: f64) -> ErrorState {
    let w0 = model.schuler_frequency();
    let (s, c) = (w0 * t).sin_cos();
    let g = model.g;
    ErrorState {
        dr: g * drift / (w0 * w0 * w0) * (s - w0 * t),
        dv: g * drift / (w0 * w0) * (c - 1.0),
        alpha: drift / w0 * s,
    }
}

/// Initial velocity error ΔV0 alone (23): `Δr = ΔV0/ω0 s`, `ΔV = ΔV0 c`, `α = ΔV0 ω0/g s`.
pub fn initial_velocity_response(model: &ErrorModel, dv0: f64, t: f64) -> ErrorState {
    let w0 = model.schuler_frequency();
    let (s, c) = (w0 * t).sin_cos();
    ErrorState {
        dr: dv0 / w0 * s,
        dv: dv0 * c,
        alpha: dv0 * w0 / model.g * s,
    }
}

/// Free vertical channel (32) with a constant accelerometer error `b`: height and
/// vertical-velocity errors `(Δh, ΔV_h)` at `t` for `Δh'' - 2ω0² Δh = b`, i.e.
/// `Δh = (Δh0 + b/2ω0²) ch(√2 ω0 t) + ΔV0/(√2 ω0) sh(√2 ω0 t) - b/2ω0²`.
pub fn vertical_free_response(w0: f64, dh0: f64, dv0: f64, accel_bias: f64, t: f64) -> (f64, f64) {
    let k = std::f64::consts::SQRT_2 * w0;
    let p = accel_bias / (k * k);
    let (ch, sh) = ((k * t).cosh(), (k * t).sinh());
    let dh = (dh0 + p) * ch + dv0 / k * sh - p;
    let dv = (dh0 + p) * k * sh + dv0 * ch;
    (dh, dv)
}

/// e-fold time of the free vertical channel `τ0 = 1 / (√2 ω0)` \[s\] (32).
pub fn vertical_e_fold_time(w0: f64) -> f64 {
    1.0 / (std::f64::consts::SQRT_2 * w0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn general_solution_is_the_sum_of_the_special_cases() {
        // Linearity: (18)/(19) with all inputs = (20) + (21) + (22) + (23) + Δr0.
        let m = ErrorModel::new(6_371_000.0, 9.81);
        let e = ConstantErrors {
            accel_bias: 1e-3,
            drift: 4.85e-8,
            alpha0: 9.7e-5,
            dv0: 1.0,
            dr0: 50.0,
        };
        for &t in &[0.0, 100.0, 2000.0, 14_400.0] {
            let all = response(&m, &e, t);
            let parts = [
                accel_bias_response(&m, e.accel_bias, t),
                initial_tilt_response(&m, e.alpha0, t),
                drift_response(&m, e.drift, t),
                initial_velocity_response(&m, e.dv0, t),
            ];
            let dr: f64 = parts.iter().map(|p| p.dr).sum::<f64>() + e.dr0;
            let dv: f64 = parts.iter().map(|p| p.dv).sum();
            let al: f64 = parts.iter().map(|p| p.alpha).sum();
            assert!((all.dr - dr).abs() < 1e-9 * (1.0 + dr.abs()));
            assert!((all.dv - dv).abs() < 1e-12);
            assert!((all.alpha - al).abs() < 1e-18);
        }
    }

    #[test]
    fn vertical_free_response_solves_32() {
        let w0 = (9.81f64 / 6_371_000.0).sqrt();
        let (h0, v0) = vertical_free_response(w0, 10.0, 0.5, 1e-3, 0.0);
        assert!((h0 - 10.0).abs() < 1e-12 && (v0 - 0.5).abs() < 1e-15);
        // Second derivative by differences: Δh'' = 2 w0^2 Δh + b.
        let (t, h) = (700.0, 0.5);
        let f = |t| vertical_free_response(w0, 10.0, 0.5, 1e-3, t).0;
        let acc = (f(t + h) - 2.0 * f(t) + f(t - h)) / (h * h);
        let want = 2.0 * w0 * w0 * f(t) + 1e-3;
        assert!((acc - want).abs() < 1e-6 * want.abs(), "{acc} vs {want}");
    }
}
