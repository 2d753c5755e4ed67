//! Semantic checks of a [`Scene`]: what the TOML grammar cannot say.

use glam::{Vec2, Vec3, Vec4};

use crate::camera::MIN_FOVY_DEG;
use crate::error::SceneError;
use crate::model::{
    ColorInput, Displacement, LightSpec, MaterialSpec, Mesh, ScalarInput, Scene, MAX_LAYERS,
    MAX_OUTPUT_SIDE, MAX_SCENE_LIGHTS, MAX_SHADING_SAMPLES,
};

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

/// Checks that every index of mesh `mi`'s triangles names one of its vertices.
fn check_indices(mi: usize, m: &Mesh) -> Result<(), SceneError> {
    let n = m.positions.len();
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
    Ok(())
}

impl Scene {
    /// Check everything a renderer relies on:
    /// output sides in `1..=MAX_OUTPUT_SIDE`; camera values finite, `0 < near < far`,
    /// `MIN_FOVY_DEG <= fovy_deg < 180`, `eye != target`, `up` not parallel to the view direction; per mesh
    /// `uvs`/`normals`/`colors` as long as `positions`, every index in range, every value finite,
    /// its texture defined; at least one mesh, each with at least one triangle.
    ///
    /// # Errors
    /// The first problem found, as [`SceneError::OutputSize`], [`SceneError::NonFinite`],
    /// [`SceneError::CameraNearFar`], [`SceneError::CameraFov`], [`SceneError::CameraDegenerate`],
    /// [`SceneError::MeshLength`], [`SceneError::IndexOutOfRange`] or
    /// [`SceneError::UnknownTexture`] or [`SceneError::Empty`].
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_output()?;
        self.validate_camera()?;
        if self.meshes.is_empty() {
            return Err(SceneError::Empty(
                "the scene has no meshes: there is nothing to render".into(),
            ));
        }
        for (mi, m) in self.meshes.iter().enumerate() {
            self.validate_mesh(mi, m)?;
        }
        self.validate_lights()?;
        if let Some(e) = &self.environment {
            e.validate()?;
        }
        for (name, m) in &self.materials {
            self.validate_material(name, m)?;
        }
        Ok(())
    }

    /// Checks that both output sides are in `1..=MAX_OUTPUT_SIDE`.
    fn validate_output(&self) -> Result<(), SceneError> {
        let o = &self.output;
        if !(1..=MAX_OUTPUT_SIDE).contains(&o.width) || !(1..=MAX_OUTPUT_SIDE).contains(&o.height) {
            return Err(SceneError::OutputSize {
                width: o.width,
                height: o.height,
                max: MAX_OUTPUT_SIDE,
            });
        }
        Ok(())
    }

    /// Checks the camera: finite values, `0 < near < far`, the field of view's range, a view
    /// direction that is neither zero nor parallel to `up`, and a finite view matrix.
    fn validate_camera(&self) -> Result<(), SceneError> {
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
        if !(c.fovy_deg >= MIN_FOVY_DEG && c.fovy_deg < 180.0) {
            return Err(SceneError::CameraFov(c.fovy_deg));
        }
        // In f64: a camera 1e30 away or a view 1e-30 long has lengths whose squares leave f32's
        // range, which would call it degenerate.
        let dir = c.target.as_dvec3() - c.eye.as_dvec3();
        let up = c.up.as_dvec3();
        let cross = dir.cross(up).length();
        // All finite here, so plain comparisons decide.
        if dir.length() == 0.0 || cross <= 1e-6 * dir.length() * up.length() {
            return Err(SceneError::CameraDegenerate {
                eye: c.eye.to_array(),
                target: c.target.to_array(),
                up: c.up.to_array(),
            });
        }
        if !c.view_from_world().is_finite() {
            return Err(SceneError::NonFinite {
                what: "camera (its view matrix: the eye's distance from the origin overflows f32)"
                    .into(),
                value: format!("eye {:?}", c.eye.to_array()),
            });
        }
        Ok(())
    }

    /// Checks mesh `mi`: at least one triangle, attributes as long as `positions`, indices in
    /// range, finite values, a defined texture, tangents as long and finite, a defined material.
    fn validate_mesh(&self, mi: usize, m: &Mesh) -> Result<(), SceneError> {
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
        check_indices(mi, m)?;
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
        if let Some(t) = &m.tangents {
            len("tangents", t.len())?;
            finite_all(mi, "tangents", t, Vec4::is_finite, |v| {
                format!("{:?}", v.to_array())
            })?;
        }
        if let Some(name) = &m.material {
            if !self.materials.contains_key(name) {
                return Err(SceneError::MeshMaterial {
                    mesh: mi,
                    reason: format!(
                        "material {name:?} is not defined (defined: {})",
                        self.materials
                            .keys()
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            }
        }
        Ok(())
    }

    fn validate_lights(&self) -> Result<(), SceneError> {
        if self.lights.len() > MAX_SCENE_LIGHTS {
            return Err(SceneError::Light(format!(
                "{} lights, more than the {MAX_SCENE_LIGHTS} a scene may have",
                self.lights.len()
            )));
        }
        for (k, l) in self.lights.iter().enumerate() {
            let (what, v, intensity) = match *l {
                LightSpec::Directional {
                    direction,
                    intensity,
                } => {
                    if direction.is_finite() && direction.as_dvec3().length() == 0.0 {
                        return Err(SceneError::Light(format!(
                            "lights[{k}].direction is zero; it points towards the light"
                        )));
                    }
                    ("direction", direction, intensity)
                }
                LightSpec::Point {
                    position,
                    intensity,
                } => ("position", position, intensity),
                LightSpec::Ambient { intensity } => ("intensity", intensity, intensity),
            };
            finite3(|| format!("lights[{k}].{what}"), v)?;
            finite3(|| format!("lights[{k}].intensity"), intensity)?;
            if intensity.min_element() < 0.0 {
                return Err(SceneError::Light(format!(
                    "lights[{k}].intensity {:?} is negative",
                    intensity.to_array()
                )));
            }
        }
        Ok(())
    }

    fn validate_material(&self, name: &str, m: &MaterialSpec) -> Result<(), SceneError> {
        let bad = |reason: String| SceneError::Material {
            name: name.to_string(),
            reason,
        };
        let unit = |key: &str, s: &ScalarInput| match s {
            ScalarInput::Value(v) if !(0.0..=1.0).contains(v) => {
                Err(bad(format!("{key} = {v} must be in [0, 1]")))
            }
            ScalarInput::Channel {
                channel, factor, ..
            } if *channel > 3 || !(0.0..=1.0).contains(factor) => Err(bad(format!(
                "{key}: channel {channel} (at most 3) with factor {factor} (in [0, 1])"
            ))),
            _ => Ok(()),
        };
        unit("roughness", &m.roughness)?;
        unit("metallic", &m.metallic)?;
        if let ColorInput::Rgb(c) = m.base_color {
            if !c.is_finite() || c.min_element() < 0.0 {
                return Err(bad(format!(
                    "base_color = {:?} must be finite and >= 0",
                    c.to_array()
                )));
            }
        }
        if !m.normal_scale.is_finite() || !m.height_scale.is_finite() {
            return Err(bad("normal_scale and height_scale must be finite".into()));
        }
        for t in m.textures() {
            if !self.textures.contains_key(t) {
                return Err(bad(format!(
                    "texture {t:?} is not defined (defined: {})",
                    self.textures.keys().cloned().collect::<Vec<_>>().join(", ")
                )));
            }
        }
        if let Some(n) = &m.normal {
            self.linear("normal map", n, "vectors").map_err(bad)?;
        }
        if let Some(h) = &m.height {
            self.linear("height map", h, "heights").map_err(bad)?;
        }
        if let Some(o) = &m.occlusion {
            self.linear("occlusion map", o, "visibilities")
                .map_err(bad)?;
        }
        if !(1..=MAX_SHADING_SAMPLES).contains(&m.shading_samples) {
            return Err(bad(format!(
                "shading_samples = {} must be in 1..={MAX_SHADING_SAMPLES}",
                m.shading_samples
            )));
        }
        if !(0.0..=1.0).contains(&m.occlusion_strength) {
            return Err(bad(format!(
                "occlusion_strength = {} must be in [0, 1]",
                m.occlusion_strength
            )));
        }
        if m.height_scale < 0.0 {
            return Err(bad(format!(
                "height_scale = {} must be at least 0",
                m.height_scale
            )));
        }
        if m.displacement != Displacement::None && !m.has_heights() {
            return Err(bad(format!(
                "displacement = \"{}\" needs a height map: give it height = \"TEXTURE\" (or \
                 layers with heights)",
                m.displacement.name()
            )));
        }
        self.validate_layers(m).map_err(bad)
    }

    /// That texture `t` (defined), read as `what`, is `color = "linear"`.
    fn linear(&self, what: &str, t: &str, holds: &str) -> Result<(), String> {
        match self.textures.get(t).map(|t| t.color) {
            Some(texel_texture::ColorSpace::Linear) | None => Ok(()),
            Some(_) => Err(format!(
                "{what} {t:?} holds {holds}, not colours: give it color = \"linear\""
            )),
        }
    }

    /// The layers of a layered material (or that a plain one has none of their keys).
    fn validate_layers(&self, m: &MaterialSpec) -> Result<(), String> {
        let d = MaterialSpec::default();
        if m.layers.is_empty() {
            let layer_keys = m.mask.is_some()
                || m.blend != d.blend
                || m.blend_depth != d.blend_depth
                || m.layer_order != d.layer_order;
            return match layer_keys {
                true => Err(
                    "mask, blend, blend_depth and layer_order belong to layered \
                             materials: give [[materials.NAME.layers]]"
                        .into(),
                ),
                false => Ok(()),
            };
        }
        if m.layers.len() > MAX_LAYERS {
            return Err(format!(
                "{} layers given; at most {MAX_LAYERS} (one per mask channel)",
                m.layers.len()
            ));
        }
        let own = m.base_color != d.base_color
            || m.roughness != d.roughness
            || m.normal.is_some()
            || m.height.is_some();
        if own {
            return Err(
                "a layered material takes base_color, roughness, normal and height \
                        from its layers: give them per layer"
                    .into(),
            );
        }
        if m.layers.len() > 1 && m.mask.is_none() {
            return Err(format!(
                "{} layers need a mask = \"TEXTURE\" to weigh them",
                m.layers.len()
            ));
        }
        if !(m.blend_depth > 0.0 && m.blend_depth <= 1.0) {
            return Err(format!("blend_depth = {} must be in (0, 1]", m.blend_depth));
        }
        if let Some(mask) = &m.mask {
            self.linear("mask", mask, "weights")?;
        }
        for (k, l) in m.layers.iter().enumerate() {
            let at = |e: String| format!("layer {k}: {e}");
            for (key, s) in [
                ("roughness", Some(&l.roughness)),
                ("height", l.height.as_ref()),
            ] {
                if let Some(ScalarInput::Value(v)) = s {
                    if !(0.0..=1.0).contains(v) {
                        return Err(at(format!("{key} = {v} must be in [0, 1]")));
                    }
                }
            }
            if let ColorInput::Rgb(c) = l.base_color {
                if !c.is_finite() || c.min_element() < 0.0 {
                    return Err(at(format!(
                        "base_color = {:?} must be finite and >= 0",
                        c.to_array()
                    )));
                }
            }
            if !l.normal_scale.is_finite() {
                return Err(at("normal_scale must be finite".into()));
            }
            if let Some(n) = &l.normal {
                self.linear("normal map", n, "vectors").map_err(at)?;
            }
            if let Some(h) = l.height.as_ref().and_then(ScalarInput::texture) {
                self.linear("height map", h, "heights").map_err(at)?;
            }
        }
        Ok(())
    }
}
