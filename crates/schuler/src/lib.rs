//! schuler: an inertial navigation toolkit.
//!
//! SI units and radians inside, `f64` everywhere; engineering units only at the edges
//! through `units`. Frames: body = front-right-down (FRD), navigation = north-east-down
//! (NED); DCMs are named `c_xy` for the transformation from frame `x` to frame `y`
//! (`v_n = c_bn * v_b`).

pub mod align;
pub mod analysis;
pub mod channel;
pub mod domain;
pub mod earth;
pub mod filter;
pub mod gnss;
pub mod imu;
pub mod lab;
pub mod nav;
pub mod refine;
pub mod rotation;
pub mod session;
pub mod sim;
pub mod units;
