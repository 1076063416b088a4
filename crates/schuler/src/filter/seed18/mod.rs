//! The flight-test paper's 18-state error model (seed 003, BINS-500NS): velocity
//! errors (3), errors of the navigation quaternion `p` (4) and of the orientation
//! quaternion `q0` (4), gyro drifts (3), accelerometer biases (3), height error (1),
//! on the quaternion free-azimuth mechanization ([`crate::nav::wander`]), with the
//! paper's position and velocity measurements `z_k` and `z_V`.
//!
//! # The mechanization the errors belong to
//!
//! Seed 003 eq. (1)–(2), in this crate's axes (wander frame `w` with `z` down):
//!
//! - `ṗ = ½ p ⊗ ρ`, `p = q_we` (wander to ECEF), `ρ = ω_ew^w = T(u, h) V` with
//!   `ρ_z = 0` (free azimuth), `u = C_ew e_z` the polar axis in `w`;
//! - `q̇0 = ½ q0 ⊗ ω_ib^b`, `q0 = q_bi = q_ei(t) ⊗ p ⊗ q_bw`, `q_ei = q_z(Ω(t − t_ref))`
//!   (the mechanization carries `q_bw`, the same rotation, see
//!   [`crate::nav::wander`]; `q0` is formed from it);
//! - `V̇ = C_bw f + g^w(u, h) − (2Ω u + ρ) × V`, `C_bw = C(p)ᵀ C(q_ei)ᵀ C(q0)` (the
//!   paper's `C3 = C0 C2ᵀ C1ᵀ`);
//! - `ḣ = −V_z`.
//!
//! # The 18 states
//!
//! `x = [δV, δp, δq0, ε, Δf, δh]`, each computed minus true: `δV = V̂ − V` (each in
//! its own free-azimuth trihedron), `δp = p̂ − p` and `δq0 = q̂0 − q0` **additive
//! 4-vectors** `[w, x, y, z]`, `ε` the residual gyro drift, `Δf` the residual
//! accelerometer bias (body axes), `δh = ĥ − h`. Offsets: [`model::VEL`],
//! [`model::NAV_Q`], [`model::ORI_Q`], [`model::GYRO`], [`model::ACCEL`],
//! [`model::HEIGHT`].
//!
//! # Linearised dynamics
//!
//! Perturbing the kinematics: `δṗ = ½ δp ⊗ ρ + ½ p ⊗ δρ`,
//! `δq̇0 = ½ δq0 ⊗ ω_ib + ½ q0 ⊗ ε`. Both homogeneous parts are the kinematics
//! themselves, so they are solved exactly by writing the additive errors in local
//! coordinates (`L`, `R`: left and right product matrices, [`model::lmat`],
//! [`model::rmat`]):
//!
//! `δp = p ⊗ (η_p, ½ φ_w) = L(p) diag(1, ½, ½, ½) [η_p; φ_w]`,
//! `δq0 = (η_0, ½ φ_i) ⊗ q0 = R(q0) diag(1, ½, ½, ½) [η_0; φ_i]`,
//!
//! `φ_w` the computed trihedron's rotation from the true one (wander axes: tilt =
//! position, `z` = the trihedron's azimuth error), `φ_i` the body's inertial attitude
//! error (inertial axes), `η = q·δq` the norm components. Substituting,
//!
//! - `η̇_p = 0`, `η̇_0 = 0` (right products by pure quaternions are skew);
//! - `φ̇_w = −ρ × φ_w + δρ`, `δρ = T δV + R_φ φ_w + R_h δh`;
//! - `φ̇_i = C_bi ε`;
//! - `δV̇ = [f×] φ_w − [f×] C_iw φ_i + C_bw Δf + G_φ φ_w + g_h δh
//!   + 2Ω [V×][u×] φ_w + [V×] δρ − [(2Ω u + ρ)×] δV`
//!   (from `Ĉ_bw = (I + (C_iw φ_i − φ_w)×) C_bw`, `δu = u × φ_w`);
//! - `δḣ = −δV_z`; `ε̇ = −ε/τ_g`, `Δḟ = −Δf/τ_a` (infinite `τ`: constants).
//!
//! `T = ∂ρ/∂V` is the curvature map of the mechanization's transport rate (exact,
//! `ρ` is linear in `V`); `R_φ, R_h, G_φ, g_h` — the transport rate's and gravity's
//! dependence on latitude (through `u`) and height — are central differences of the
//! Earth model at the point (steps 1e-6 rad and 1 m; the error is O(step²)), so the
//! model is first-order exact on any [`crate::earth::EarthModel`]. This is
//! [`model::Point::dynamics`], `ẏ = F y`, `x = M y` with `M` the block-diagonal map
//! above; in the additive coordinates `ẋ = (M F M⁻¹ + Ṁ M⁻¹) x`, whose `Ṁ M⁻¹` terms
//! are exactly the `½ δp ⊗ ρ`, `½ δq0 ⊗ ω_ib` above.
//!
//! **Transition over a step** ([`model::transition`]): `Φ = M(t_k) Φ_y M(t_{k−1})⁻¹`,
//! `Φ_y = I + A + A²/2 + A³/6`, `A = F T` with the interval's mean specific force (as
//! the psi-angle model, [`crate::filter::error_model`]). The fast part of `δq0`'s
//! dynamics (the body's rotation, up to rad/s) is carried exactly by `M`, not by the
//! truncated series. **Process noise**: velocity random walk through `C_bw`, angle
//! random walk through `C_bi`, bias walks; `Q_d = M Q_y Mᵀ`.
//!
//! # The redundant (norm) directions
//!
//! A unit quaternion has three degrees of freedom; `η_p`, `η_0` (the components of
//! `δp`, `δq0` along `p`, `q0`) change no rotation, no measurement sees them
//! (`H M` has zero columns there) and the dynamics keep them constant. They are
//! given zero prior variance and the covariance is projected after every propagation
//! and update, `P ← Π P Πᵀ`, `Π = diag(I, I − p pᵀ, I − q0 q0ᵀ, I)`: the linearised
//! normalisation `d(q/|q|) = (I − q qᵀ) dq`, applied to the covariance as the
//! feedback applies it to the state (`p ← (p̂ − δp)/|p̂ − δp|`). Why projection rather
//! than a pseudo-measurement `p·δp = 0`: the constraint is exact (the mechanization
//! renormalises), so it carries no noise, and a noise-free pseudo-measurement is
//! the same projection done with a singular innovation covariance; without either,
//! the frozen-coefficient `Φ_y` leaks O((ωT)⁴) of the moving norm direction into
//! the covariance at each step and `P` would not stay rank 16.
//!
//! The remaining 16 directions are the 15 physical errors of the psi-angle model plus
//! one gauge: the free-azimuth trihedron's own azimuth error `φ_w,z` together with
//! `δV = −φ_w,z e_z × V` leaves position, velocity relative to the Earth and attitude
//! unchanged ([`model::Point::physical`] maps `x` to those), so no measurement sees
//! it and its variance stays at its prior — where the 18-state and 15-state filters'
//! covariances differ. The prior takes the true trihedron parallel to the computed
//! one about the vertical ([`model::Point::from_physical`]).
//!
//! # Measurements (seed 003, inertial-satellite mode)
//!
//! ([`measure`]) `z_k = [(φ − φ_G)(R_M + h), (λ − λ_G)(R_N + h) cos φ, h − h_G]`
//! with `φ, λ` read from `p` by the seed's formulas; to first order `[d_N, d_E] =
//! R_z(α) T⁻¹ φ_w,xy` (a displacement `d` tilts the trihedron by `T d`, as `ρ = T V`)
//! and `δh`. `z_V = C4 V − V_G` in east, north, up, `C4 = P_enu R_z(α)`: to first
//! order `C4 (δV + δα e_z × V)`, `δα = φ_w,z + tan φ δλ` (the trihedron's azimuth
//! error plus the meridian convergence of the position error). Both are written in
//! latitude, longitude and azimuth and lose their meaning at a pole: within
//! [`measure::POLE_COS_LAT`] they are not formed and the filter coasts. The paper's
//! measurements are of the INS itself: no lever arm, and no scale-factor or
//! barometer states ([`Unsupported`]).

pub mod measure;
pub mod model;
pub mod run;

pub use run::{Seed18, Unsupported, check};
