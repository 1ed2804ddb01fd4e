//! Poses and pinhole camera intrinsics.
//!
//! World frame: origin at the table centre, x to the right of the camera image, y towards the
//! top of the image ("back"), z up. Camera frames follow the OpenCV convention (x right,
//! y down, z along the optical axis).

use glam::{DMat3, DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// A rigid transform from a local frame to the world frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: DVec3,
    pub rotation: DQuat,
}

impl Pose {
    pub const IDENTITY: Pose = Pose {
        position: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
    };

    pub fn new(position: DVec3, rotation: DQuat) -> Self {
        Self { position, rotation }
    }

    /// What makes this pose unusable, if anything: a position or rotation not finite, or a
    /// rotation that is not a unit quaternion (a zero one turns every point to the origin).
    pub fn check(&self) -> Result<(), String> {
        if !self.position.is_finite() {
            return Err(format!("position {} is not finite", self.position));
        }
        let norm = self.rotation.length();
        if !(norm.is_finite() && (norm - 1.0).abs() < 1e-6) {
            return Err(format!(
                "rotation {} has length {norm}, expected a unit quaternion",
                self.rotation
            ));
        }
        Ok(())
    }

    /// A camera at `eye` whose optical axis points at `target`; image "down" is world -z
    /// projected into the image plane, or world -y when looking straight down or up.
    pub fn camera_looking_at(eye: DVec3, target: DVec3) -> Option<Self> {
        let forward = (target - eye).try_normalize()?;
        let mut down = DVec3::NEG_Z;
        if down.cross(forward).length() < 1e-9 {
            down = DVec3::NEG_Y;
        }
        let x = down.cross(forward).normalize();
        let y = forward.cross(x);
        let rotation = DQuat::from_mat3(&DMat3::from_cols(x, y, forward));
        Some(Self {
            position: eye,
            rotation,
        })
    }

    /// A tool pose whose z axis (the sensing direction of the tactile pad) points down, with
    /// the pad's x axis along world x.
    pub fn tool_down(position: DVec3) -> Self {
        Self {
            position,
            rotation: DQuat::from_rotation_x(std::f64::consts::PI),
        }
    }

    /// `tool_down`, turned `yaw_rad` about the world's vertical.
    pub fn tool_down_turned(position: DVec3, yaw_rad: f64) -> Self {
        Self {
            position,
            rotation: DQuat::from_rotation_z(yaw_rad)
                * DQuat::from_rotation_x(std::f64::consts::PI),
        }
    }

    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.position
    }

    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// This pose after `local`: the transform taking `local`'s frame through `local`, then
    /// this pose (a flange's pose composed with a board's pose on the flange).
    pub fn compose(&self, local: &Pose) -> Pose {
        Pose::new(
            self.transform_point(local.position),
            self.rotation * local.rotation,
        )
    }

    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.inverse();
        Self {
            position: -(rotation * self.position),
            rotation,
        }
    }
}

/// Pinhole intrinsics (pixels). Defaults are the TactEx paper's RealSense colour stream.
/// Pixel (x, y)'s centre is at (u, v) = (x, y), as in OpenCV and librealsense, so a real
/// camera's calibration and the twin's renders mean the same point by the same pixel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraIntrinsics {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Default for CameraIntrinsics {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            fx: 608.5,
            fy: 606.9,
            cx: 309.4,
            cy: 213.83,
        }
    }
}

/// The longest focal length a camera's intrinsics may give, in pixels (a 4096 px wide image
/// seen through a 2.3 degree field of view).
pub const MAX_FOCAL_PX: f64 = 1e5;

impl CameraIntrinsics {
    /// What makes these intrinsics unusable, if anything: a camera has 1 to 4096 pixels a side
    /// (the most an image tactex reads has), positive finite focal lengths and a finite
    /// principal point.
    pub fn check(&self) -> Result<(), String> {
        let side = 1..=crate::image_file::MAX_SIDE_PX;
        let finite = [self.fx, self.fy, self.cx, self.cy]
            .iter()
            .all(|v| v.is_finite());
        // A focal length of 1e-300 px or a principal point 1e9 px off the image maps the
        // table onto a height map of gigabytes; lenses give 1 to 1e5 px and a centre on the chip.
        let focal = 1.0..=MAX_FOCAL_PX;
        if !(finite
            && focal.contains(&self.fx)
            && focal.contains(&self.fy)
            && side.contains(&self.width)
            && side.contains(&self.height)
            && (0.0..=f64::from(self.width)).contains(&self.cx)
            && (0.0..=f64::from(self.height)).contains(&self.cy))
        {
            return Err(format!(
                "need 0 < width, height <= {}, fx, fy in 1..={MAX_FOCAL_PX} px and cx, cy inside the image (got {}x{}, fx {}, fy {}, cx {}, cy {})",
                crate::image_file::MAX_SIDE_PX,
                self.width,
                self.height,
                crate::printable::short_number(self.fx),
                crate::printable::short_number(self.fy),
                crate::printable::short_number(self.cx),
                crate::printable::short_number(self.cy)
            ));
        }
        Ok(())
    }

    /// Pixel coordinates of a point in the camera frame, or None behind the camera.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        (p.z > 1e-9).then(|| (self.fx * p.x / p.z + self.cx, self.fy * p.y / p.z + self.cy))
    }

    /// The pixel whose area holds image point (u, v) (pixel x spans u in [x - 0.5, x + 0.5)),
    /// or None outside the image.
    pub fn pixel_at(&self, u: f64, v: f64) -> Option<(u32, u32)> {
        let (x, y) = ((u + 0.5).floor(), (v + 0.5).floor());
        (x >= 0.0 && y >= 0.0 && x < self.width as f64 && y < self.height as f64)
            .then_some((x as u32, y as u32))
    }

    /// The camera-frame point at pixel (u, v) with depth `z` along the optical axis.
    pub fn back_project(&self, u: f64, v: f64, z: f64) -> DVec3 {
        DVec3::new((u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A focal length of 1e-300 px or a centre 1e9 px off the chip sized a height map in
    /// gigabytes; intrinsics no lens has are refused.
    #[test]
    fn intrinsics_no_lens_has_are_refused() {
        assert!(CameraIntrinsics::default().check().is_ok());
        for edit in [
            |k: &mut CameraIntrinsics| k.fx = 1e-300,
            |k: &mut CameraIntrinsics| k.fy = 1e6,
            |k: &mut CameraIntrinsics| k.cx = 1e9,
            |k: &mut CameraIntrinsics| k.cy = -1.0,
        ] {
            let mut k = CameraIntrinsics::default();
            edit(&mut k);
            assert!(k.check().is_err(), "{k:?}");
        }
    }

    #[test]
    fn a_pixel_holds_the_points_within_half_a_pixel_of_its_centre() {
        let k = CameraIntrinsics::default();
        assert_eq!(k.pixel_at(3.0, 4.0), Some((3, 4)));
        assert_eq!(k.pixel_at(3.49, 4.49), Some((3, 4)));
        assert_eq!(k.pixel_at(3.5, 3.5), Some((4, 4)));
        assert_eq!(k.pixel_at(-0.5, -0.5), Some((0, 0)));
        assert_eq!(k.pixel_at(-0.51, 0.0), None);
        assert_eq!(k.pixel_at(639.49, 479.49), Some((639, 479)));
        assert_eq!(k.pixel_at(639.5, 0.0), None);
    }

    #[test]
    fn camera_looking_straight_down_maps_world_x_right_and_y_up_in_image() {
        let cam = Pose::camera_looking_at(DVec3::new(0.0, 0.0, 0.7), DVec3::ZERO).unwrap();
        let k = CameraIntrinsics::default();
        let to_cam = cam.inverse();
        let (u0, v0) = k.project(to_cam.transform_point(DVec3::ZERO)).unwrap();
        let (u1, _) = k
            .project(to_cam.transform_point(DVec3::new(0.1, 0.0, 0.0)))
            .unwrap();
        let (_, v1) = k
            .project(to_cam.transform_point(DVec3::new(0.0, 0.1, 0.0)))
            .unwrap();
        assert!((u0 - k.cx).abs() < 1e-9 && (v0 - k.cy).abs() < 1e-9);
        assert!(u1 > u0, "world +x must be image right");
        assert!(v1 < v0, "world +y must be image up");
    }

    #[test]
    fn back_projection_inverts_projection() {
        let k = CameraIntrinsics::default();
        let p = DVec3::new(0.03, -0.08, 0.65);
        let (u, v) = k.project(p).unwrap();
        assert!((k.back_project(u, v, p.z) - p).length() < 1e-12);
    }

    #[test]
    fn pose_inverse_round_trips() {
        let pose = Pose::new(DVec3::new(1.0, 2.0, 3.0), DQuat::from_rotation_z(0.7));
        let p = DVec3::new(-0.3, 0.2, 0.9);
        assert!((pose.inverse().transform_point(pose.transform_point(p)) - p).length() < 1e-12);
    }

    #[test]
    fn tool_down_points_the_pad_at_the_table() {
        let tool = Pose::tool_down(DVec3::new(0.0, 0.0, 0.2));
        assert!((tool.transform_vector(DVec3::Z) - DVec3::NEG_Z).length() < 1e-12);
        assert!((tool.transform_vector(DVec3::X) - DVec3::X).length() < 1e-12);
    }
}
