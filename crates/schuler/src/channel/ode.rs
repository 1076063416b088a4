//! Classical fourth-order Runge-Kutta step for `x' = f(t, x)` on fixed-size vectors.
//!
//! Why RK4: the models here are smooth (Schuler frequency ~1.2e-3 rad/s, turns and
//! rotations resolved with >= 10 steps), so the local error `O((w dt)^5)` is ~1e-12 or
//! less per step at the default steps: nonlinear-versus-linear differences are then set
//! by the physics, not by the integrator.

use nalgebra::SVector;

/// One RK4 step of length `h` from `(t, x)` for `x' = f(t, x)`; returns `x(t + h)`.
pub fn rk4_step<const N: usize>(
    f: &mut impl FnMut(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N> {
    let k1 = f(t, x);
    let k2 = f(t + 0.5 * h, &(x + k1 * (0.5 * h)));
    let k3 = f(t + 0.5 * h, &(x + k2 * (0.5 * h)));
    let k4 = f(t + h, &(x + k3 * h));
    x + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

/// Most steps a run may take (5e7: about 14 h at 1 kHz), so that no input can ask for an
/// unbounded allocation.
pub const MAX_STEPS: f64 = 5e7;

/// Checks that `duration / dt` stays within [`MAX_STEPS`].
pub(crate) fn check_steps(duration: f64, dt: f64) -> Result<(), super::ChannelError> {
    let steps = duration / dt;
    if steps > MAX_STEPS {
        return Err(super::ChannelError::OutOfRange {
            name: "step dt",
            value: dt,
            reason: format!("{steps:.3e} steps for {duration} s; at most {MAX_STEPS:e}"),
        });
    }
    Ok(())
}

/// The time grid of a run: `n` steps of `dt` covering `[0, duration]`, the last step
/// shortened so the grid ends exactly at `duration`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Nominal step \[s\].
    pub dt: f64,
    /// Run length \[s\].
    pub duration: f64,
    /// Number of steps.
    pub steps: usize,
}

impl Grid {
    /// The grid for `duration` and `dt` (both already validated positive).
    pub fn new(duration: f64, dt: f64) -> Self {
        // Tolerate round-off so that 4 h / 0.1 s is 144000 steps, not 144001.
        let steps = ((duration / dt) - 1e-9).ceil().max(1.0) as usize;
        Self {
            dt,
            duration,
            steps,
        }
    }

    /// Time of grid point `k` (0..=steps) \[s\].
    pub fn time(&self, k: usize) -> f64 {
        if k >= self.steps {
            self.duration
        } else {
            k as f64 * self.dt
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn harmonic_oscillator_one_period() {
        // x'' = -x over 2 pi with h = 0.01: RK4 global error ~ T h^4 / 120 ~ 5e-10.
        let mut f = |_t: f64, x: &Vector2<f64>| Vector2::new(x[1], -x[0]);
        let n = 628;
        let h = std::f64::consts::TAU / n as f64;
        let mut x = Vector2::new(1.0, 0.0);
        for k in 0..n {
            x = rk4_step(&mut f, k as f64 * h, &x, h);
        }
        assert!((x[0] - 1.0).abs() < 1e-8 && x[1].abs() < 1e-8, "{x}");
    }

    #[test]
    fn grid_ends_at_duration() {
        let g = Grid::new(14_400.0, 0.1);
        assert_eq!(g.steps, 144_000);
        let g = Grid::new(10.05, 0.1);
        assert_eq!(g.steps, 101);
        assert_eq!(g.time(101), 10.05);
    }
}
