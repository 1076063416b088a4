//! The textbook laboratory: lecture 22's platform, analytic and gyro-free INS
//! ([`platform`]), driven by a trajectory's truth from the simulator so they can be
//! compared with the strapdown mechanizations of [`crate::nav`] on the same motion.
//! Unlike `nav`, `filter` and `align`, the laboratory may import [`crate::sim`]. The
//! single-channel models stay in [`crate::channel`], whose vertical-loop gains and
//! fault detector the operational [`crate::nav::BaroLoop`] uses.

pub mod platform;
