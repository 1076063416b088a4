//! The error budget: the navigation error covariance along a true trajectory with the
//! filter's own linear error model, and each error source's share of it (no random
//! draws).
//!
//! - [`source`]: the independent sources (priors, sensor noise terms, measurement
//!   noises), each the filter's configuration with every other term zero;
//! - [`propagation`]: the whole filter and each source alone through the same closed
//!   loop `(I − K H) Φ`, whose shares add up to the whole.
//!
//! The closed forms it meets (tests): the textbook's constant-error responses
//! (20)–(23) and the free vertical channel (32) ([`crate::channel::closed`]).

pub mod propagation;
pub mod source;

pub use propagation::{Budget, Part, nav_variances};
pub use source::{MODEL_SOURCES, Source};

#[cfg(test)]
mod tests;
