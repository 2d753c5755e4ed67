//! Camera matrices: look-at and OpenGL perspective, thin documented wrappers over glam.
//!
//! Conventions (conventions.md, "Coordinates"): right-handed world, the camera looks down its `-z`,
//! OpenGL clip space with NDC `z` in `[-1, 1]` (near maps to -1, far to +1). `clip_from_world` is
//! `perspective(..) * look_at(..) * world_from_model`.

use glam::{Mat4, Vec3};

/// The view matrix `view_from_world` of a camera at `eye` looking at `target`, with `up` giving the
/// upward direction (gluLookAt; glam `Mat4::look_at_rh`).
///
/// In view space the camera sits at the origin and looks down `-z`, `+y` is up and `+x` right.
/// Edge case: `eye == target`, or `up` parallel to the viewing direction, gives a matrix with NaN
/// entries; triangles transformed by it are then skipped as non-finite.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    Mat4::look_at_rh(eye, target, up)
}

/// The OpenGL perspective projection `clip_from_view` (gluPerspective; glam `Mat4::perspective_rh_gl`).
///
/// `fovy_rad` is the full vertical field of view in radians, `aspect = width / height`, `near` and
/// `far` are positive distances along `-z` (`0 < near < far`). A view-space point at depth `-near` maps
/// to NDC `z = -1`, at `-far` to `z = +1`; `w_clip = -z_view` (the distance in front of the eye).
/// Out-of-range arguments give non-finite or meaningless matrices; the rasterizer then skips or clips
/// the affected triangles rather than panicking.
pub fn perspective(fovy_rad: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    Mat4::perspective_rh_gl(fovy_rad, aspect, near, far)
}

/// The viewport transform of conventions.md: NDC `(x, y)` to continuous pixel coordinates of a
/// `width x height` frame, `x = (x_ndc + 1) / 2 * W`, `y = (1 - y_ndc) / 2 * H` (row 0 at the top;
/// pixel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`).
pub fn viewport(x_ndc: f64, y_ndc: f64, width: u32, height: u32) -> (f64, f64) {
    (
        (x_ndc + 1.0) * 0.5 * f64::from(width),
        (1.0 - y_ndc) * 0.5 * f64::from(height),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    #[test]
    fn near_and_far_map_to_ndc_bounds() {
        let p = perspective(1.0, 1.5, 0.1, 100.0);
        let near = p * Vec4::new(0.0, 0.0, -0.1, 1.0);
        let far = p * Vec4::new(0.0, 0.0, -100.0, 1.0);
        assert!((near.z / near.w + 1.0).abs() < 1e-5);
        assert!((far.z / far.w - 1.0).abs() < 1e-5);
        assert!((near.w - 0.1).abs() < 1e-7);
    }

    #[test]
    fn look_at_puts_target_on_minus_z() {
        let v = look_at(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -5.0), Vec3::Y);
        let t = v.transform_point3(Vec3::new(0.0, 1.0, -5.0));
        assert!((t - Vec3::new(0.0, 0.0, -5.0)).length() < 1e-6);
    }

    #[test]
    fn viewport_corners() {
        assert_eq!(viewport(-1.0, 1.0, 640, 480), (0.0, 0.0));
        assert_eq!(viewport(1.0, -1.0, 640, 480), (640.0, 480.0));
        assert_eq!(viewport(0.0, 0.0, 640, 480), (320.0, 240.0));
    }
}
