//! The camera: a right-handed look-at view and an OpenGL perspective projection (DESIGN.md).

use glam::{Mat4, Vec3};

/// The narrowest vertical field of view a camera may have, in degrees. At 0.01 degrees a pixel of
/// a 4096-row image subtends 4.3e-8 radians, about f32's relative precision (6e-8), so view
/// coordinates still place a point within about a pixel; narrower views quantise the image into
/// blocks of pixels and, far narrower, overflow the projection and draw nothing. They are refused.
pub const MIN_FOVY_DEG: f32 = 0.01;

/// A perspective camera looking from `eye` towards `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position, world units.
    pub eye: Vec3,
    /// The point looked at, world units.
    pub target: Vec3,
    /// The world's up direction (not necessarily perpendicular to the view direction).
    pub up: Vec3,
    /// Vertical field of view in degrees, in `(0, 180)`.
    pub fovy_deg: f32,
    /// Near plane distance, `> 0`.
    pub near: f32,
    /// Far plane distance, `> near`.
    pub far: f32,
}

impl Camera {
    /// The view matrix: world to camera space (right-handed, the camera looks down -z).
    pub fn view_from_world(&self) -> Mat4 {
        let dir = self.target - self.eye;
        let well_scaled = |v: Vec3| {
            let l = v.length_squared();
            l.is_normal() && l.is_finite()
        };
        if well_scaled(dir) && well_scaled(self.up) && well_scaled(dir.cross(self.up)) {
            return Mat4::look_at_rh(self.eye, self.target, self.up);
        }
        // A distance or an up vector whose square over- or underflows in f32 (an eye 1e30 away, a
        // view 1e-25 long): the basis is found in f64, where those squares are exact enough.
        glam::DMat4::look_at_rh(
            self.eye.as_dvec3(),
            self.target.as_dvec3(),
            self.up.as_dvec3(),
        )
        .as_mat4()
    }

    /// The OpenGL perspective projection for `aspect = width / height` (NDC z in `[-1, 1]`,
    /// `gluPerspective`).
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh_gl(self.fovy_deg.to_radians(), aspect, self.near, self.far)
    }

    /// `clip_from_view(aspect) * view_from_world()`: world positions to clip space.
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    /// The camera orbited by `degrees` about the `up` axis through the target (counter-clockwise
    /// seen from above): the eye keeps its height and distance, and still looks at the target.
    /// Unchanged when `up` is zero or not finite.
    pub fn orbited(&self, degrees: f32) -> Camera {
        let Some(axis) = self.up.try_normalize() else {
            return *self;
        };
        let r = glam::Quat::from_axis_angle(axis, degrees.to_radians());
        Camera {
            eye: self.target + r * (self.eye - self.target),
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    #[test]
    fn target_projects_to_centre_and_planes_to_ndc_bounds() {
        let cam = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(-2.0, 0.5, -4.0),
            up: Vec3::Y,
            fovy_deg: 60.0,
            near: 0.5,
            far: 100.0,
        };
        let m = cam.clip_from_world(16.0 / 9.0);
        let dir = (cam.target - cam.eye).normalize();
        let ndc = |p: Vec3| {
            let c = m * p.extend(1.0);
            c.truncate() / c.w
        };
        let t = ndc(cam.target);
        assert!(t.x.abs() < 1e-5 && t.y.abs() < 1e-5);
        assert!((ndc(cam.eye + dir * cam.near).z + 1.0).abs() < 1e-4);
        assert!((ndc(cam.eye + dir * cam.far).z - 1.0).abs() < 1e-3);
        // w is the distance along the view direction.
        let c = m * (cam.eye + dir * 7.0).extend(1.0);
        assert!((c.w - 7.0).abs() < 1e-4);
    }

    #[test]
    fn an_orbit_keeps_height_distance_and_target() {
        let cam = Camera {
            eye: Vec3::new(0.0, 1.0, 0.0),
            target: Vec3::new(0.0, 0.75, -10.0),
            up: Vec3::Y,
            fovy_deg: 50.0,
            near: 0.05,
            far: 100.0,
        };
        let o = cam.orbited(90.0);
        // A quarter turn about +y through the target takes the eye from +z of it to +x of it.
        assert!(
            (o.eye - Vec3::new(10.0, 1.0, -10.0)).length() < 1e-4,
            "{}",
            o.eye
        );
        assert_eq!(
            (o.target, o.up, o.fovy_deg),
            (cam.target, cam.up, cam.fovy_deg)
        );
        let small = cam.orbited(0.1);
        assert!(((small.eye - cam.target).length() - (cam.eye - cam.target).length()).abs() < 1e-5);
        assert_eq!(small.eye.y, 1.0);
        assert_eq!(cam.orbited(0.0), cam);
    }

    #[test]
    fn fov_edge_maps_to_ndc_one() {
        let cam = Camera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            fovy_deg: 90.0,
            near: 0.1,
            far: 10.0,
        };
        let c = cam.clip_from_world(2.0) * Vec4::new(0.0, 1.0, -1.0, 1.0);
        assert!((c.y / c.w - 1.0).abs() < 1e-6);
        let c = cam.clip_from_world(2.0) * Vec4::new(2.0, 0.0, -1.0, 1.0);
        assert!((c.x / c.w - 1.0).abs() < 1e-6);
    }
}
