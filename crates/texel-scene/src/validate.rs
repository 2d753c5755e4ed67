//! Semantic checks of a [`Scene`]: what the TOML grammar cannot say.

use glam::{Vec2, Vec3, Vec4};

use crate::error::SceneError;
use crate::model::{Scene, MAX_OUTPUT_SIDE};

fn finite3(what: impl Fn() -> String, v: Vec3) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::NonFinite {
            what: what(),
            value: format!("{:?}", v.to_array()),
        })
    }
}

fn finite_all<T: Copy>(
    mesh: usize,
    attr: &str,
    values: &[T],
    ok: impl Fn(T) -> bool,
    show: impl Fn(T) -> String,
) -> Result<(), SceneError> {
    match values.iter().position(|&v| !ok(v)) {
        None => Ok(()),
        Some(i) => Err(SceneError::NonFinite {
            what: format!("meshes[{mesh}].{attr}[{i}]"),
            value: show(values[i]),
        }),
    }
}

impl Scene {
    /// Check everything a renderer relies on:
    /// output sides in `1..=MAX_OUTPUT_SIDE`; camera values finite, `0 < near < far`,
    /// `0 < fovy_deg < 180`, `eye != target`, `up` not parallel to the view direction; per mesh
    /// `uvs`/`normals`/`colors` as long as `positions`, every index in range, every value finite,
    /// its texture defined; at least one mesh, each with at least one triangle.
    ///
    /// # Errors
    /// The first problem found, as [`SceneError::OutputSize`], [`SceneError::NonFinite`],
    /// [`SceneError::CameraNearFar`], [`SceneError::CameraFov`], [`SceneError::CameraDegenerate`],
    /// [`SceneError::MeshLength`], [`SceneError::IndexOutOfRange`] or
    /// [`SceneError::UnknownTexture`] or [`SceneError::Empty`].
    pub fn validate(&self) -> Result<(), SceneError> {
        let o = &self.output;
        if !(1..=MAX_OUTPUT_SIDE).contains(&o.width) || !(1..=MAX_OUTPUT_SIDE).contains(&o.height) {
            return Err(SceneError::OutputSize {
                width: o.width,
                height: o.height,
                max: MAX_OUTPUT_SIDE,
            });
        }
        let c = &self.camera;
        finite3(|| "camera.eye".into(), c.eye)?;
        finite3(|| "camera.target".into(), c.target)?;
        finite3(|| "camera.up".into(), c.up)?;
        for (what, v) in [
            ("camera.fovy_deg", c.fovy_deg),
            ("camera.near", c.near),
            ("camera.far", c.far),
        ] {
            if !v.is_finite() {
                return Err(SceneError::NonFinite {
                    what: what.into(),
                    value: v.to_string(),
                });
            }
        }
        if !(c.near > 0.0 && c.far > c.near) {
            return Err(SceneError::CameraNearFar {
                near: c.near,
                far: c.far,
            });
        }
        if !(c.fovy_deg > 0.0 && c.fovy_deg < 180.0) {
            return Err(SceneError::CameraFov(c.fovy_deg));
        }
        let dir = c.target - c.eye;
        let cross = dir.cross(c.up).length();
        // All finite here, so plain comparisons decide.
        if dir.length() == 0.0 || cross <= 1e-6 * dir.length() * c.up.length() {
            return Err(SceneError::CameraDegenerate {
                eye: c.eye.to_array(),
                target: c.target.to_array(),
                up: c.up.to_array(),
            });
        }
        if self.meshes.is_empty() {
            return Err(SceneError::Empty(
                "the scene has no meshes: there is nothing to render".into(),
            ));
        }
        for (mi, m) in self.meshes.iter().enumerate() {
            if m.triangles.is_empty() {
                return Err(SceneError::Empty(format!(
                    "meshes[{mi}] has no triangles: there is nothing to render"
                )));
            }
            let n = m.positions.len();
            let len = |attribute: &'static str, got: usize| {
                if got == n {
                    Ok(())
                } else {
                    Err(SceneError::MeshLength {
                        mesh: mi,
                        attribute,
                        expected: n,
                        got,
                    })
                }
            };
            len("uvs", m.uvs.len())?;
            if let Some(v) = &m.normals {
                len("normals", v.len())?;
            }
            if let Some(v) = &m.colors {
                len("colors", v.len())?;
            }
            for (ti, t) in m.triangles.iter().enumerate() {
                if let Some(&index) = t.iter().find(|&&i| i as usize >= n) {
                    return Err(SceneError::IndexOutOfRange {
                        mesh: mi,
                        triangle: ti,
                        index,
                        vertices: n,
                    });
                }
            }
            let s3 = |v: Vec3| format!("{:?}", v.to_array());
            finite_all(mi, "positions", &m.positions, Vec3::is_finite, s3)?;
            finite_all(mi, "uvs", &m.uvs, Vec2::is_finite, |v| {
                format!("{:?}", v.to_array())
            })?;
            if let Some(v) = &m.normals {
                finite_all(mi, "normals", v, Vec3::is_finite, s3)?;
            }
            if let Some(v) = &m.colors {
                finite_all(mi, "colors", v, Vec4::is_finite, |v| {
                    format!("{:?}", v.to_array())
                })?;
            }
            if !self.textures.contains_key(&m.texture) {
                return Err(SceneError::UnknownTexture {
                    mesh: mi,
                    name: m.texture.clone(),
                    defined: self.textures.keys().cloned().collect::<Vec<_>>().join(", "),
                });
            }
        }
        Ok(())
    }
}
