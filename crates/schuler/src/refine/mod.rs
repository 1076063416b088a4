//! In-motion refinement on the invariant of seed 003, eqs (7)–(12): what it observes,
//! and the mode that makes it observe something.
//!
//! # The observation
//!
//! The flight-test paper (seed 003) refines the attitude and the gyro drifts in flight
//! without external aids through the invariant (7): over a step `[t_{i−1}, t_i]`
//!
//! ```text
//! z_i = ∫ { C0ᵀ Θ̇ − C1ᵀ [ω + δ̇] } dτ − [0, 0, Ω Δt_i]ᵀ                      (7)
//! ```
//!
//! with `Θ̇` the gyro output, `C0` the body's orientation relative to the inertial
//! frame (quaternion `q0` of (1)), `C1` the free-azimuth frame's (quaternion `p1`),
//! `ω` that frame's rate relative to the Earth, `δ̇` the body's rate relative to the
//! frame, obtained from the Euler angles of `C3 = C0 C2ᵀ C1ᵀ` and their rates (8)–(10),
//! the rates from (11)–(12), and `Ω` the Earth's rate about the polar axis. In this
//! crate's names (`c_xy` turns coordinates in frame `x` into frame `y`,
//! `v_y = c_xy v_x`): `C0 = c_biᵀ`, `C2 = c_eiᵀ` (the Earth turned by `Ω t`),
//! `C1ᵀ` is read as the frame-to-inertial `c_ni = c_ei c_ne` (so that every term of (7)
//! is in inertial axes; the paper calls `C1` the frame's orientation "relative to the
//! inertial frame"), `C3 = c_nb`, and `ω = ω_en^n`, `δ̇ = ω_nb^n`. Then (7) reads
//!
//! ```text
//! z = ∫ ( ĉ_bi Θ̇ − c_ni (ω_en^n + ω_nb^n) − Ω^i ) dτ,
//! ```
//!
//! the body's inertial rate measured by the gyros minus the same rate built from its
//! parts, `ω_ib = ω_ie + ω_en + ω_nb` ([`invariant`]).
//!
//! # Without an independent source of angle rates it is identically zero
//!
//! If `δ̇` comes from the system's own `C3` through (11)–(12), as the paper writes,
//! `ċ_nb = −[ω_nb^b×] c_nb` with `ċ_bi = c_bi [Θ̇×]`, `ċ_ei = c_ei [ω_ie^e×]`,
//! `ċ_ne = c_ne [ω_en^n×]` gives ([`own_rate_nb`])
//! `ω_nb^b = Θ̇ − c_nb (ω_ie^n + ω_en^n)`, and substituting,
//! `ĉ_bi Θ̇ − c_ni ω_en^n − ĉ_bi ω_nb^b − Ω^i = ĉ_bi ĉ_nb(ω_ie^n + ω_en^n) − c_ni ω_en^n −
//! c_ni ω_ie^n = 0` for **any** gyro drift, attitude error, position error or motion:
//! every term is computed from the same `Θ̇` and `ω`, so their errors cancel exactly.
//! The Euler-angle route of (8)–(10) is the same vector in other coordinates
//! ([`nav_rate_from_euler_rates`]), so it cancels too (up to the numerical
//! differentiation's error). `tests/refine_invariant.rs` shows it on a maneuvering
//! flight at 70° N with a 0.5 deg/h drift and a 1° attitude error: `|z|` stays at
//! rounding level where the drift alone would give `2.4e-6` rad per 1-s step.
//!
//! # With an independent source: what it observes
//!
//! The paper names no source for `δ̇`. The mode therefore takes `ω_nb^n` from an
//! independent unit: on a helicopter, the angle rates of a second inertial unit or
//! of the flight-control attitude-and-heading reference, in the same body axes
//! (a strapdown unit measures `ω_ib^b` directly; its `ω_nb^n = c_bn ω_ib^b − ω_in^n`).
//! Let the system's inertial attitude error be `ψ` (inertial axes,
//! `ĉ_bi = (I − [ψ×]) c_bi`), the drift `ε` (body), the reference's rate error `n`
//! (nav axes), and let the navigation frame be known (its error from a position
//! error `δr` enters as `(ω_en + ω_nb) × δr/R`, neglected here). To first order
//!
//! ```text
//! z = ∫ ( ω_ib^i × ψ + c_bi ε − c_ni n ) dτ = [A×] ψ(t_i) + (B + [A×]B − M) ε − ∫ c_ni n,
//! A = ∫ ω_ib^i dτ,  B = ∫ c_bi dτ,  M = ∫ [ω_ib^i(τ)×] B(τ) dτ,
//! ```
//!
//! using `ψ̇ = −c_bi ε` inside the step ([`InvariantWindow`]). While the inertial rate
//! `ω = ω_ib^i` is constant, `d(c_bi ε)/dt = ω × c_bi ε` makes the rate of `z` constant
//! too: `ż = ω × ψ(0) + c_bi(0) ε`, one 3-vector however long the motion lasts. Hence:
//!
//! - along the rotation axis `u`, the drift is seen alone (`u · ż = u · c_bi ε`): with
//!   white rate noise of density `q` in the reference, `1/σ² = 1/σ₀² + T/q²`;
//! - across it, only `|ω| [u×] ψ + ε` is seen: tilt and drift share what they learn
//!   (`σ_ψ = a b / √(ω² a² + b²)` from priors `a`, `b`) until the rate or the axis
//!   changes (turn entries and exits, rolls, pitch changes) and separates them;
//! - the attitude error along the rotation axis is never seen. At rest `ω = Ω`: the
//!   classic gyrocompass, in which drift and heading are inseparable, blind to heading
//!   at the pole; turns about the vertical add nothing about heading; only rotations
//!   about a horizontal axis reveal it when `Ω` is vertical;
//! - a reference with its own bias `β` makes the mode estimate `ε − β`: it refines the
//!   drift only if its rates are as good as the system's gyros, and refines the
//!   attitude by `|A| |ψ|` against its noise (a 90° turn shows a `1′` error as
//!   `4.6e-4` rad).
//!
//! `tests/refine_invariant.rs` checks each claim: the own-source invariant at rounding
//! level; the independent-source `z` against `H [ψ, ε]` and zero for an error along the
//! rotation axis; the filter's standard deviations against the closed forms above at
//! the pole in a constant-rate turn, the heading at its prior through left and right
//! turns, and seen after a roll.
//!
//! [`RefineFilter`] is the six-state Kalman filter on `[ψ, ε]` with this observation.
//!
//! [`SecondUnitRefinement`] is the mode with a second strapdown unit as the source
//! (its rates turned by its own attitude): the observation is then the difference of
//! the two units' inertial rotations, it sees the *differences* of their attitude
//! errors and drifts, and its noise is the units' own angle random walk, shared with
//! the attitude difference's process noise ([`TwoUnitFilter`]).
//! `tests/refine_second_unit.rs` flies it with two simulated FOG units in a hovering
//! helicopter near the pole: the vertical drift difference converges as
//! `1/σ² = 1/σ₀² + T/(q₁² + q₂²)`, tilt and horizontal drift separate after the
//! pirouettes' rate changes, the heading difference stays at its prior until a roll.

mod filter;
mod invariant;
mod second_unit;

pub use filter::{RefineFilter, RefineNoise};
pub use invariant::{
    InvariantWindow, earth_to_inertial, invariant, nav_rate_from_euler_rates, own_rate_nb,
    reference_increment,
};
pub use second_unit::{SecondUnitRefinement, TwoUnitFilter};
