//! The viewer's fly camera: move along the view direction and sideways, look around by yaw
//! (about the scene's up) and pitch, change the field of view. It starts as the scene's camera,
//! unchanged bit for bit, so the first frame is `texel render`'s.

use glam::{Quat, Vec3};
use texel::scene::Camera;

/// Steepest pitch reached by looking up or down, degrees from the horizon.
const MAX_PITCH_DEG: f32 = 89.0;

/// Field-of-view range of the scroll wheel, degrees.
pub(crate) const FOV_RANGE: (f32, f32) = (5.0, 150.0);

/// A camera the viewer moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Fly {
    /// The camera as it is now.
    pub camera: Camera,
    /// World units per second of movement.
    pub speed: f32,
}

/// Movement in camera axes: `forward` along the view, `right`, `up` along the scene's up; each
/// `-1`, `0` or `1` (keys held), scaled by speed and time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Motion {
    /// Forward (+) or back (-).
    pub forward: f32,
    /// Right (+) or left (-).
    pub right: f32,
    /// Up (+) or down (-).
    pub up: f32,
}

impl Motion {
    /// Whether any direction is held.
    pub(crate) fn is_moving(&self) -> bool {
        self.forward != 0.0 || self.right != 0.0 || self.up != 0.0
    }
}

impl Fly {
    /// Start at `camera`, moving `speed` world units per second.
    pub(crate) fn new(camera: Camera, speed: f32) -> Fly {
        Fly { camera, speed }
    }

    fn forward(&self) -> Vec3 {
        (self.camera.target - self.camera.eye).normalize_or(Vec3::NEG_Z)
    }

    fn up(&self) -> Vec3 {
        self.camera.up.normalize_or(Vec3::Y)
    }

    /// Move for `seconds` with `motion` (times 4 with `fast`): eye and target move together.
    pub(crate) fn step(&mut self, motion: Motion, seconds: f32, fast: bool) {
        let forward = self.forward();
        let up = self.up();
        let right = forward.cross(up).normalize_or(Vec3::X);
        let d = (forward * motion.forward + right * motion.right + up * motion.up)
            * (self.speed * seconds * if fast { 4.0 } else { 1.0 });
        if d.is_finite() && d != Vec3::ZERO {
            self.camera.eye += d;
            self.camera.target += d;
        }
    }

    /// Turn by `yaw` degrees about the scene's up (positive turns right) and `pitch` degrees
    /// (positive looks up), keeping the pitch within 89 degrees of the horizon.
    pub(crate) fn look(&mut self, yaw_deg: f32, pitch_deg: f32) {
        let up = self.up();
        let to_target = self.camera.target - self.camera.eye;
        let dist = to_target.length().max(1e-3);
        let forward = self.forward();
        let pitch_now = forward.dot(up).clamp(-1.0, 1.0).asin().to_degrees();
        let pitch = (pitch_now + pitch_deg).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG) - pitch_now;
        let right = forward.cross(up).normalize_or(Vec3::X);
        let rotation = Quat::from_axis_angle(up, -yaw_deg.to_radians())
            * Quat::from_axis_angle(right, pitch.to_radians());
        let f = (rotation * forward).normalize_or(forward);
        if f.is_finite() {
            self.camera.target = self.camera.eye + f * dist;
        }
    }

    /// Change the vertical field of view by `delta` degrees, within [`FOV_RANGE`].
    pub(crate) fn zoom(&mut self, delta_deg: f32) {
        self.camera.fovy_deg = (self.camera.fovy_deg + delta_deg).clamp(FOV_RANGE.0, FOV_RANGE.1);
    }
}

/// Movement speed of the fly camera: half the distance from the eye to the point looked at per
/// second (the scene's scale where the camera is: the ground plane's camera stands 1 unit high and
/// looks 10 units ahead, so it moves 5 units a second), at most the scene's bounding-box diagonal
/// and at least 0.001 world units.
pub(crate) fn movement_speed(scene: &texel::PreparedScene) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for m in &scene.scene.meshes {
        for &p in &m.positions {
            if p.is_finite() {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    let diagonal = (hi - lo).length();
    let c = &scene.scene.camera;
    let reach = (c.target - c.eye).length() / 2.0;
    let speed = if diagonal.is_finite() {
        reach.min(diagonal)
    } else {
        reach
    };
    if speed.is_finite() {
        speed.max(1e-3)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fovy_deg: 60.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn moving_translates_eye_and_target_by_speed_times_time() {
        let mut f = Fly::new(camera(), 2.0);
        f.step(
            Motion {
                forward: 1.0,
                ..Motion::default()
            },
            0.5,
            false,
        );
        assert!((f.camera.eye - Vec3::new(0.0, 1.0, 4.0)).length() < 1e-6);
        assert!((f.camera.target - Vec3::new(0.0, 1.0, -1.0)).length() < 1e-6);
        f.step(
            Motion {
                right: 1.0,
                up: -1.0,
                ..Motion::default()
            },
            1.0,
            true,
        );
        // Right of a camera looking down -z is +x; fast is 4x.
        assert!((f.camera.eye - Vec3::new(8.0, -7.0, 4.0)).length() < 1e-5);
    }

    #[test]
    fn looking_turns_about_up_and_clamps_the_pitch() {
        let mut f = Fly::new(camera(), 1.0);
        f.look(90.0, 0.0);
        let d = (f.camera.target - f.camera.eye).normalize();
        assert!((d - Vec3::X).length() < 1e-5, "{d}");
        f.look(0.0, 200.0);
        let d = (f.camera.target - f.camera.eye).normalize();
        let pitch = d.y.asin().to_degrees();
        assert!((pitch - MAX_PITCH_DEG).abs() < 1e-3, "{pitch}");
        f.look(0.0, -400.0);
        let d = (f.camera.target - f.camera.eye).normalize();
        assert!((d.y.asin().to_degrees() + MAX_PITCH_DEG).abs() < 1e-3);
        // The distance to the target stays.
        assert!(((f.camera.target - f.camera.eye).length() - 5.0).abs() < 1e-4);
    }

    #[test]
    fn zoom_stays_in_range_and_nothing_moves_until_asked() {
        let mut f = Fly::new(camera(), 1.0);
        assert_eq!(f.camera, camera());
        f.zoom(-1000.0);
        assert_eq!(f.camera.fovy_deg, FOV_RANGE.0);
        f.zoom(1000.0);
        assert_eq!(f.camera.fovy_deg, FOV_RANGE.1);
        f.step(Motion::default(), 1.0, false);
        assert_eq!(f.camera.eye, camera().eye);
    }
}
