//! What the lighting tests share: a lit unit square and the camera looking at it.

#![allow(dead_code)]

use glam::{Mat4, Vec2, Vec3, Vec4};
use texel_raster::{camera, Vertex};

/// Frame width, pixels.
pub(crate) const W: u32 = 96;
/// Frame height, pixels.
pub(crate) const H: u32 = 64;

/// The square `[-1, 1]^2` in z = 0 facing +z, u along +x, v down (-y) (2 world units per unit of
/// u and of v), tangent +x with `w = 1` (`cross(z, x) = +y`, up the image).
pub(crate) fn plane() -> Vec<Vertex> {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| {
            let mut v = Vertex::new(
                Vec3::new(x, y, 0.0),
                Vec2::new((x + 1.0) / 2.0, (1.0 - y) / 2.0),
            );
            v.normal = Vec3::Z;
            v.tangent = Vec4::new(1.0, 0.0, 0.0, 1.0);
            v
        })
        .collect()
}

/// The two counter-clockwise triangles of [`plane`].
pub(crate) const PLANE_TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

/// The camera: `clip_from_world` and the eye.
pub(crate) fn view() -> (Mat4, Vec3) {
    let eye = Vec3::new(0.4, 0.3, 3.0);
    let m = camera::perspective(50f32.to_radians(), W as f32 / H as f32, 0.1, 10.0)
        * camera::look_at(eye, Vec3::ZERO, Vec3::Y);
    (m, eye)
}
