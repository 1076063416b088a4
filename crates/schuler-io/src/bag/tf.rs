//! The robot's static transform tree (`/tf_static`, `tf2_msgs/TFMessage`) and the
//! IMU's mounting it gives.
//!
//! A `geometry_msgs/TransformStamped` with `header.frame_id` P and `child_frame_id`
//! C holds C's orientation in P as a quaternion q: a vector of C's axes is
//! `v_P = R(q)·v_C` (tf2, REP 103). Going up the tree from the IMU's frame to the base
//! frame, `C_base_imu = R(q_n)···R(q_1)`. The base frame's axes are FLU (REP 103: x
//! forward, y left, z up), schuler's body FRD, so the IMU's axes go to FRD by
//! `C_vs = diag(1, −1, −1)·C_base_imu` (FLU to FRD is a half turn about x).
//! tf2 frame names have no leading slash; ROS 1's tf allowed one, so it is dropped.

use super::messages::TransformStamped;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion};
use std::collections::HashMap;

/// A frame's name as tf2 spells it (no leading `/`).
pub fn frame_name(s: &str) -> &str {
    s.trim_start_matches('/')
}

/// How far a quaternion's norm may be from 1 [-] (tf2 refuses a transform whose
/// quaternion is further than this from unit length, then normalizes).
const NORM_TOLERANCE: f64 = 1e-3;

/// Each frame's parent and its orientation in it, as the last transform naming the
/// frame as child gave them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TfTree {
    parents: HashMap<String, (String, UnitQuaternion<f64>)>,
}

impl TfTree {
    /// Takes in a transform; a quaternion far from unit length is refused (field
    /// and reason).
    pub fn insert(&mut self, t: &TransformStamped) -> Result<(), (String, String)> {
        let [x, y, z, w] = t.rotation;
        let q = Quaternion::new(w, x, y, z);
        let norm = q.norm();
        if (norm - 1.0).abs() > NORM_TOLERANCE {
            return Err((
                "transforms.transform.rotation".to_owned(),
                format!(
                    "quaternion {x}, {y}, {z}, {w} of {} in {} has norm {norm}, not 1",
                    t.child_frame_id, t.header.frame_id
                ),
            ));
        }
        self.parents.insert(
            frame_name(&t.child_frame_id).to_owned(),
            (
                frame_name(&t.header.frame_id).to_owned(),
                UnitQuaternion::from_quaternion(q),
            ),
        );
        Ok(())
    }

    /// Whether the tree has no transform.
    pub fn is_empty(&self) -> bool {
        self.parents.is_empty()
    }

    /// The parent of `frame`, if a transform names it.
    pub fn parent(&self, frame: &str) -> Option<&str> {
        self.parents.get(frame_name(frame)).map(|(p, _)| p.as_str())
    }

    /// `C_to_from`, turning vectors of frame `from`'s axes into frame `to`'s, where
    /// `to` is `from` or one of its ancestors; else an error giving the chain found.
    pub fn rotation(&self, from: &str, to: &str) -> Result<Matrix3<f64>, String> {
        let (from, to) = (frame_name(from), frame_name(to));
        let mut c = Matrix3::identity();
        let mut frame = from;
        let mut chain = vec![from];
        while frame != to {
            let Some((parent, q)) = self.parents.get(frame) else {
                return Err(format!(
                    "frame {to} is not above {from} in /tf_static (its chain: {})",
                    chain.join(" -> ")
                ));
            };
            if chain.contains(&parent.as_str()) {
                return Err(format!(
                    "/tf_static has a loop: {} -> {parent}",
                    chain.join(" -> ")
                ));
            }
            c = q.to_rotation_matrix().into_inner() * c;
            frame = parent;
            chain.push(frame);
        }
        Ok(c)
    }
}

/// From a ROS base frame's FLU axes to FRD (REP 103): `diag(1, −1, −1)`.
pub fn flu_to_frd() -> Matrix3<f64> {
    Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, -1.0, -1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bag::messages::Header;
    use nalgebra::Vector3;

    fn transform(parent: &str, child: &str, q: UnitQuaternion<f64>) -> TransformStamped {
        TransformStamped {
            header: Header {
                sec: 0,
                nanosec: 0,
                frame_id: parent.into(),
            },
            child_frame_id: child.into(),
            translation: [0.0; 3],
            rotation: [q.i, q.j, q.k, q.w],
        }
    }

    /// imu_link rolled −90° then yawed 90° from base_link (tf2's RPY: fixed axes,
    /// `R = Rz(yaw)·Ry(pitch)·Rx(roll)`), worked by hand: Rx(−90°) keeps x, takes y
    /// to −z and z to y; Rz(90°) takes x to y, y to −x and keeps z. So the IMU's x is
    /// the base's y (left), its y the base's −z (down), its z the base's −x (back).
    /// A chain through a mid frame gives the same product; an unrelated frame names
    /// the chain.
    #[test]
    fn a_rolled_and_yawed_imu_frame_by_hand() {
        let q = UnitQuaternion::from_euler_angles((-90f64).to_radians(), 0.0, 90f64.to_radians());
        let mut tree = TfTree::default();
        tree.insert(&transform("/base_link", "imu_link", q))
            .expect("unit");
        assert_eq!(tree.parent("imu_link"), Some("base_link"));
        let c = tree.rotation("imu_link", "base_link").expect("chain");
        // Columns: the IMU's x, y, z in the base's FLU axes.
        let expected = Matrix3::from_columns(&[Vector3::y(), -Vector3::z(), -Vector3::x()]);
        assert!((c - expected).abs().max() < 1e-15, "{c}");
        // In FRD: x → (0, −1, 0) (left), y → (0, 0, 1) (down), z → (−1, 0, 0) (back).
        let frd = flu_to_frd() * c;
        let expected = Matrix3::from_columns(&[-Vector3::y(), Vector3::z(), -Vector3::x()]);
        assert!((frd - expected).abs().max() < 1e-15, "{frd}");
        // Through a mid frame: base_link -> mount (yaw 90°) -> imu (roll −90°).
        let mut tree = TfTree::default();
        let yaw = UnitQuaternion::from_euler_angles(0.0, 0.0, 90f64.to_radians());
        let roll = UnitQuaternion::from_euler_angles((-90f64).to_radians(), 0.0, 0.0);
        tree.insert(&transform("base_link", "mount", yaw))
            .expect("unit");
        tree.insert(&transform("mount", "imu", roll)).expect("unit");
        let c2 = tree.rotation("imu", "base_link").expect("chain");
        assert!((c2 - c).abs().max() < 1e-15, "{c2}");
        let e = tree.rotation("imu", "odom").expect_err("not above");
        assert!(e.contains("imu -> mount -> base_link"), "{e}");
        assert_eq!(tree.rotation("imu", "imu"), Ok(Matrix3::identity()));
    }

    #[test]
    fn non_unit_quaternions_are_refused() {
        let mut t = transform("base_link", "imu", UnitQuaternion::identity());
        t.rotation = [0.0, 0.0, 0.0, 2.0];
        let e = TfTree::default().insert(&t).expect_err("norm 2");
        assert_eq!(e.0, "transforms.transform.rotation");
    }
}
