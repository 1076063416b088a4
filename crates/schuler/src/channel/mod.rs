//! The textbook's single-channel INS and SINS, their error theory, and the vertical
//! channel (SEEDS.md, first section; textbook "Introduction to inertial navigation",
//! MIPT 2022, equations (5)-(38)).
//!
//! The picture: a point M moves along the equator of a homogeneous sphere of radius `a`
//! (the non-rotating textbook Earth, optionally rotating at `ω`); one coordinate, the
//! longitude λ. The reference trihedron Mx has x1 up and x2 along the equator. A platform
//! INS (6)/(9) keeps an accelerometer on a gyro platform commanded at `V/a` (+ `ω`); a
//! single-channel SINS (7)/(26) carries accelerometers along body axes p1, p2 and a gyro
//! along p3 and computes the body angle `D` to the horizon.
//!
//! * [`models`]: the nonlinear ideal and perturbed systems, integrated side by side.
//! * [`linear`]: the linear error models (13)/(15) and (28)/(29), the fundamental
//!   matrix (16), and the vertical loop's matrix (37).
//! * [`closed`]: the closed forms (18)-(23) and (32).
//! * [`expm`]: the matrix exponential of an arbitrary square matrix.
//! * [`profile`]: the vehicle's speed along the equator and its body angle `D(t)`.
//! * [`run`]: one scenario run three ways (nonlinear, linear, closed form).
//! * [`measure`]: what a run shows: Schuler period, slopes, e-fold times, settling.
//! * [`vertical`], [`reference`](mod@reference), [`detector`], [`kalman`]: the vertical channel
//!   (30)-(32), the reference-aided loop (33)-(38) with its fault detector and
//!   prediction mode, and its Kalman-filter variant with time-varying gains.
//!
//! Everything is SI: metres, seconds, radians.

pub mod closed;
pub mod detector;
pub mod error;
pub mod expm;
pub mod kalman;
pub mod linear;
pub mod measure;
pub mod models;
pub mod ode;
pub mod profile;
pub mod reference;
pub mod run;
pub mod vertical;

pub use error::ChannelError;
