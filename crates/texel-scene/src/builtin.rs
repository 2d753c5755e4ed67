//! Built-in scenes, available as `builtin:NAME`.
//!
//! `ground`, `zoneplate` and `triangle` are TOML files compiled into the crate (`src/builtin/`;
//! `ground` is byte for byte `scenes/ground.toml`); `ground-rotated`, `cube`, `sphere`,
//! the globes and the lit scenes but `glossy`, `bricks` and `terrain` are built in code.

use std::f32::consts::PI;
use std::path::Path;

use glam::{Vec2, Vec3, Vec4};
use texel_texture::mapping::sphere::SurfaceProjection;
use texel_texture::{AddressMode, ColorSpace};

use crate::camera::Camera;
use crate::error::SceneError;
use crate::model::{Mesh, Output, Scene, SphereUv, TextureSource, TextureSpec};
use crate::procedural::Procedural;

/// The ground plane TOML (identical to `scenes/ground.toml`).
pub const GROUND_TOML: &str = include_str!("builtin/ground.toml");
/// The zone plate scene's TOML.
pub const ZONEPLATE_TOML: &str = include_str!("builtin/zoneplate.toml");
/// The barycentric triangle scene's TOML.
pub const TRIANGLE_TOML: &str = include_str!("builtin/triangle.toml");
/// The glossy normal-mapped plane's TOML.
pub const GLOSSY_TOML: &str = include_str!("builtin/glossy.toml");
/// The brick wall's TOML.
pub(crate) const BRICKS_TOML: &str = include_str!("builtin/bricks.toml");
/// The layered terrain's TOML.
pub(crate) const TERRAIN_TOML: &str = include_str!("builtin/terrain.toml");

/// Angle by which `ground-rotated` turns the ground's uvs, in degrees.
pub const GROUND_ROTATION_DEG: f32 = 30.0;

/// The names `builtin:NAME` accepts, in presentation order:
/// - `ground`: a checkerboard plane receding to the horizon (= `scenes/ground.toml`);
/// - `ground-rotated`: the same with its uvs rotated by 30 degrees about uv (0, 0), so the checks
///   run diagonally to the view (anisotropy off the screen axes);
/// - `zoneplate`: a zone plate on a square seen at a grazing angle;
/// - `cube`: a cube with a grid texture on each face, seen from above a corner;
/// - `sphere`: a UV sphere with a latitude-longitude grid (15 degree cells), u wrapping, its uvs
///   the equirect mapping (evaluated per pixel unless asked per vertex);
/// - `globe`: the sphere wearing a Mercator map (cut at 85.05 degrees) of parallels, meridians
///   and Tissot's discs, seen from above so the polar cap shows;
/// - `globe-equirect`: the same globe from an equirect map;
/// - `triangle`: the barycentric colour triangle (red, green, blue vertices, white texture).
pub fn builtin_names() -> &'static [&'static str] {
    &[
        "ground",
        "ground-rotated",
        "zoneplate",
        "cube",
        "sphere",
        "globe",
        "globe-equirect",
        "triangle",
    ]
}

/// Built-in scenes lit by lights and shaded with materials (`builtin:NAME` accepts them too):
/// - `glossy`: a glossy plane, normal-mapped with bumps, receding to the horizon under a low
///   light from the far side (specular aliasing);
/// - `bricks`: a brick wall with mortar joints as a height map (parallax occlusion mapping),
///   seen along its length, from 50 degrees to grazing;
/// - `terrain`: ground receding to 200 m with four layers (grass, rock, sand, snow) blended by a
///   mask and their heights, bump-mapped from the blended heights;
/// - `knot`: a clay torus knot resting on a square of ground under a sky and a sun, its uvs one
///   non-overlapping atlas ([`knot_mesh`]): the model `texel bake-ao` bakes in the demo;
/// - `mirror-spheres`: a mirror sphere and a glossy one (rough metal) in the procedural sky,
///   which is also the background: reflections of an environment map;
/// - `mirror-plane`: a rippled mirror floor receding to the horizon under the procedural sky
///   (`mirror_plane_mesh`): grazing reflections, whose footprints in the map grow long towards
///   the horizon.
pub fn shaded_builtin_names() -> &'static [&'static str] {
    &[
        "glossy",
        "bricks",
        "terrain",
        "knot",
        "mirror-spheres",
        "mirror-plane",
    ]
}

fn from_toml(name: &str, text: &str) -> Result<Scene, SceneError> {
    Scene::from_toml_str(text, Path::new(&format!("builtin:{name}")))
}

/// The built-in scene `name` ([`builtin_names`]).
///
/// # Errors
/// [`SceneError::UnknownBuiltin`].
pub fn builtin(name: &str) -> Result<Scene, SceneError> {
    match name {
        "ground" => from_toml(name, GROUND_TOML),
        "ground-rotated" => {
            let mut s = from_toml("ground", GROUND_TOML)?;
            let (sin, cos) = GROUND_ROTATION_DEG.to_radians().sin_cos();
            for m in &mut s.meshes {
                for uv in &mut m.uvs {
                    *uv = Vec2::new(cos * uv.x - sin * uv.y, sin * uv.x + cos * uv.y);
                }
            }
            Ok(s)
        }
        "zoneplate" => from_toml(name, ZONEPLATE_TOML),
        "triangle" => from_toml(name, TRIANGLE_TOML),
        "glossy" => from_toml(name, GLOSSY_TOML),
        "bricks" => from_toml(name, BRICKS_TOML),
        "terrain" => from_toml(name, TERRAIN_TOML),
        "cube" => Ok(cube()),
        "sphere" => Ok(sphere()),
        "globe" => Ok(globe(true)),
        "globe-equirect" => Ok(globe(false)),
        "knot" => Ok(knot()),
        "mirror-spheres" => Ok(mirror_spheres()),
        "mirror-plane" => Ok(mirror_plane()),
        _ => Err(SceneError::UnknownBuiltin {
            name: name.to_string(),
            available: [builtin_names(), shaded_builtin_names()]
                .concat()
                .join(", "),
        }),
    }
}

fn one_texture(name: &str, p: Procedural) -> std::collections::BTreeMap<String, TextureSpec> {
    [(
        name.to_string(),
        TextureSpec::new(TextureSource::Procedural(p), ColorSpace::Srgb),
    )]
    .into()
}

/// A 4x4 opaque white texture named `white` (a draw's texture under a constant base colour).
fn white_texture() -> std::collections::BTreeMap<String, TextureSpec> {
    one_texture(
        "white",
        Procedural::Solid {
            width: 4,
            height: 4,
            rgba: [255, 255, 255, 255],
        },
    )
}

/// A metal (`metallic = 1`) of linear colour `rgb` and perceptual `roughness`.
fn metal(rgb: Vec3, roughness: f32) -> crate::model::MaterialSpec {
    use crate::model::{ColorInput, MaterialSpec, ScalarInput};
    MaterialSpec {
        base_color: ColorInput::Rgb(rgb),
        roughness: ScalarInput::Value(roughness),
        metallic: ScalarInput::Value(1.0),
        ..Default::default()
    }
}

/// The procedural sky, `width` texels wide, as the only light and the background.
fn sky_environment(width: u32) -> Option<crate::environment::EnvironmentSpec> {
    use crate::environment::{EnvironmentSource, EnvironmentSpec, Sky};
    Some(EnvironmentSpec {
        mapping: texel_texture::mapping::sphere::Mapping::Equirect,
        source: EnvironmentSource::Sky(Sky {
            width,
            ..Sky::default()
        }),
        intensity: Vec3::ONE,
        background: true,
    })
}

/// A mesh with no vertices yet (normals to come), `texture`, clamped, no material.
fn empty_mesh(texture: &str) -> Mesh {
    Mesh {
        positions: Vec::new(),
        uvs: Vec::new(),
        normals: Some(Vec::new()),
        colors: None,
        triangles: Vec::new(),
        texture: texture.into(),
        address_mode_u: AddressMode::ClampToEdge,
        address_mode_v: AddressMode::ClampToEdge,
        filters: None,
        material: None,
        tangents: None,
        uv_mapping: None,
    }
}

/// A cube of side 2 centred at the origin; each face maps the whole texture (uv (0, 0) at the
/// face's top-left seen from outside), triangles counter-clockwise from outside, face normals.
fn cube() -> Scene {
    // (normal, right, up) per face: the face's corners are normal +- right +- up.
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    let mut mesh = empty_mesh("grid");
    for (n, r, u) in faces {
        let base = mesh.positions.len() as u32;
        // Bottom-left, bottom-right, top-right, top-left.
        for (sr, su, uv) in [
            (-1.0, -1.0, Vec2::new(0.0, 1.0)),
            (1.0, -1.0, Vec2::new(1.0, 1.0)),
            (1.0, 1.0, Vec2::new(1.0, 0.0)),
            (-1.0, 1.0, Vec2::new(0.0, 0.0)),
        ] {
            mesh.positions.push(n + r * sr + u * su);
            mesh.uvs.push(uv);
            if let Some(ns) = &mut mesh.normals {
                ns.push(n);
            }
        }
        mesh.triangles
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    Scene {
        output: Output {
            width: 960,
            height: 540,
            background: [0, 0, 0, 255],
        },
        camera: Camera {
            eye: Vec3::new(3.2, 2.6, 4.2),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_deg: 40.0,
            near: 0.1,
            far: 100.0,
        },
        textures: one_texture(
            "grid",
            Procedural::Grid {
                width: 512,
                height: 512,
                cells: 8,
                line_width: 4.0,
            },
        ),
        meshes: vec![mesh],
        lights: Vec::new(),
        materials: Default::default(),
        environment: None,
    }
}

/// Longitude segments and latitude rings of the built-in sphere.
const SPHERE_SEGMENTS: u32 = 64;
const SPHERE_RINGS: u32 = 32;

/// The built-in sphere's mesh (see [`sphere`]), with `texture`, its uvs the equirect mapping.
fn sphere_mesh(texture: &str) -> Mesh {
    sphere_mesh_mapped(texture, SurfaceProjection::Equirect)
}

/// A unit UV sphere centred at the origin: vertex (s, r) at longitude `2 pi s / 64` (0 facing
/// `+z`, increasing towards `+x`) and colatitude `pi r / 32`, with uv = `projection`'s at the
/// vertex ([`SurfaceProjection::uv`]: `u = s / 64`, equirect `v = r / 32`, Mercator's `v` clamped
/// at its cut) and the mapping recorded for per-pixel evaluation. The seam column is duplicated at
/// `u = 1` and each pole triangle has its own pole vertex at its column's `u`; u repeats, v clamps.
fn sphere_mesh_mapped(texture: &str, projection: SurfaceProjection) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=SPHERE_RINGS {
        let theta = PI * r as f32 / SPHERE_RINGS as f32;
        for s in 0..=SPHERE_SEGMENTS {
            let phi = 2.0 * PI * s as f32 / SPHERE_SEGMENTS as f32;
            // Longitude 0 faces +z (towards the camera); increasing eastwards (+x).
            positions.push(Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ));
            let v = match projection {
                SurfaceProjection::Equirect => r as f32 / SPHERE_RINGS as f32,
                SurfaceProjection::Mercator { .. } => {
                    let lat = std::f64::consts::FRAC_PI_2 - f64::from(theta);
                    let d = glam::DVec3::new(lat.cos(), lat.sin(), 0.0);
                    projection.uv(d).y as f32
                }
            };
            uvs.push(Vec2::new(s as f32 / SPHERE_SEGMENTS as f32, v));
        }
    }
    let row = SPHERE_SEGMENTS + 1;
    let mut triangles = Vec::new();
    for r in 0..SPHERE_RINGS {
        for s in 0..SPHERE_SEGMENTS {
            let a = r * row + s; // top-left (north, west)
            let b = a + row; // bottom-left
                             // Counter-clockwise seen from outside: west-north, west-south, east-south, east-north.
            if r != 0 {
                triangles.push([a, b, a + 1]);
            }
            if r != SPHERE_RINGS - 1 {
                triangles.push([a + 1, b, b + 1]);
            }
        }
    }
    let normals = Some(positions.clone());
    Mesh {
        positions,
        uvs,
        normals,
        colors: None::<Vec<Vec4>>,
        triangles,
        texture: texture.into(),
        address_mode_u: AddressMode::Repeat,
        address_mode_v: AddressMode::ClampToEdge,
        filters: None,
        material: None,
        tangents: None,
        uv_mapping: Some(SphereUv {
            projection,
            centre: Vec3::ZERO,
        }),
    }
}

/// The `sphere` scene: the built-in sphere with its equirect uv ([`sphere_mesh_mapped`]) wearing
/// a latitude-longitude grid of 15-degree cells.
fn sphere() -> Scene {
    let grid = Procedural::Grid {
        width: 1024,
        height: 512,
        cells: 24,
        line_width: 3.0,
    };
    sphere_scene(
        Vec3::new(0.0, 0.9, 3.0),
        ("latlong", grid),
        SurfaceProjection::Equirect,
    )
}

/// The `globe` (Mercator, `mercator = true`) and `globe-equirect` scenes: the built-in sphere
/// wearing [`Procedural::Globe`]'s map in that projection, seen from 35 degrees above the
/// equator so the north polar cap (past Mercator's cut) shows, with the seam (the red prime
/// meridian) facing the camera. Unlit.
fn globe(mercator: bool) -> Scene {
    let map = Procedural::Globe {
        width: 2048,
        height: if mercator { 2048 } else { 1024 },
        mercator,
    };
    let projection = map
        .globe_projection()
        .unwrap_or(SurfaceProjection::Equirect);
    sphere_scene(Vec3::new(0.0, 1.8, 2.6), ("globe", map), projection)
}

/// The built-in sphere ([`sphere_mesh_mapped`] in `projection`) wearing texture `map` (name and
/// generator), unlit, at 960 x 540 on black, seen from `eye` towards its centre (the origin)
/// with a 45-degree field of view.
fn sphere_scene(
    eye: Vec3,
    (name, map): (&str, Procedural),
    projection: SurfaceProjection,
) -> Scene {
    Scene {
        output: Output {
            width: 960,
            height: 540,
            background: [0, 0, 0, 255],
        },
        camera: Camera {
            eye,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_deg: 45.0,
            near: 0.1,
            far: 100.0,
        },
        textures: one_texture(name, map),
        meshes: vec![sphere_mesh_mapped(name, projection)],
        lights: Vec::new(),
        materials: Default::default(),
        environment: None,
    }
}

/// The `mirror-spheres` scene: two spheres of radius 1 side by side in the procedural sky, a
/// mirror (`metallic = 1`, `roughness = 0`) on the left and brushed copper (`roughness = 0.35`)
/// on the right; no lights but the environment, which is also the background.
fn mirror_spheres() -> Scene {
    let placed = |x: f32, material: &str| {
        let mut m = sphere_mesh("white");
        for p in &mut m.positions {
            *p += Vec3::new(x, 0.0, 0.0);
        }
        // A white texture: nothing to gain from evaluating the mapping per pixel.
        m.uv_mapping = None;
        m.material = Some(material.into());
        m
    };
    Scene {
        output: Output {
            width: 960,
            height: 540,
            background: [0, 0, 0, 255],
        },
        camera: Camera {
            eye: Vec3::new(0.0, 0.6, 5.2),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fovy_deg: 40.0,
            near: 0.1,
            far: 100.0,
        },
        textures: white_texture(),
        meshes: vec![placed(-1.15, "mirror"), placed(1.15, "copper")],
        lights: Vec::new(),
        materials: [
            (
                "mirror".to_string(),
                metal(Vec3::new(0.95, 0.93, 0.88), 0.0),
            ),
            (
                "copper".to_string(),
                metal(Vec3::new(0.95, 0.64, 0.54), 0.35),
            ),
        ]
        .into(),
        environment: sky_environment(1024),
    }
}

/// The ripples of [`mirror_plane_mesh`]: (wave vector `(k_x, k_z)` in radians per unit,
/// amplitude in units) of `h(x, z) = sum a sin(k_x x + k_z z)`.
pub(crate) const RIPPLES: [(f32, f32, f32); 3] =
    [(0.35, 1.3, 0.1), (-0.9, 0.8, 0.06), (1.6, 0.5, 0.03)];

/// The floor of `mirror-plane`: flat at `y = 0`, from `x = -60` to `60` and `z = 1` (behind the
/// eye at the origin) to `z = -300`, whose normals are those of the ripples [`RIPPLES`]
/// (`n = normalize(-dh/dx, 1, -dh/dz)`; the geometry stays flat, as a normal map would leave it).
/// A flat mirror shows the environment as a virtual image at the pixel's own angular size, so
/// its lookups are never minified; ripples make the reflected direction change faster than the
/// view, most of all where the view grazes the floor. 161 columns by 400 rows whose spacing grows
/// geometrically with distance (2.2 % per row, 0.05 units at the eye), so every row of
/// triangles covers about the same number of screen rows and the ripples are resolved by the
/// vertices (two a wavelength) to about 100 units away.
pub(crate) fn mirror_plane_mesh() -> Mesh {
    let mut mesh = empty_mesh("white");
    mesh.address_mode_u = AddressMode::Repeat;
    mesh.address_mode_v = AddressMode::Repeat;
    let (cols, rows) = (161u32, 400u32);
    let ratio = (301.0f32 / 0.05).powf(1.0 / (rows - 1) as f32);
    for r in 0..rows {
        // Distance from z = 1: 0 for the first row, then 0.05 ratio^(r - 1) ... 301.
        let d = if r == 0 {
            0.0
        } else {
            0.05 * ratio.powi(r as i32 - 1)
        };
        let z = 1.0 - d.min(301.0);
        for c in 0..cols {
            let x = -60.0 + 120.0 * c as f32 / (cols - 1) as f32;
            let (mut hx, mut hz) = (0.0, 0.0);
            for (kx, kz, a) in RIPPLES {
                let s = (kx * x + kz * z).cos() * a;
                hx += s * kx;
                hz += s * kz;
            }
            mesh.positions.push(Vec3::new(x, 0.0, z));
            mesh.uvs.push(Vec2::new(x, z));
            if let Some(ns) = &mut mesh.normals {
                ns.push(Vec3::new(-hx, 1.0, -hz).normalize());
            }
        }
    }
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            let a = r * cols + c;
            let b = a + cols; // one row further away (-z)
                              // Counter-clockwise seen from above (+y): a, a + 1, b + 1 and a, b + 1, b.
            mesh.triangles.extend([[a, a + 1, b + 1], [a, b + 1, b]]);
        }
    }
    mesh.material = Some("mirror".into());
    mesh
}

/// The `mirror-plane` scene: [`mirror_plane_mesh`], a silver mirror (`metallic = 1`,
/// `roughness = 0`), the eye 1 unit above it looking just below the horizon (as `ground`), the
/// procedural sky (2048 wide) as the only light and the background.
fn mirror_plane() -> Scene {
    Scene {
        output: Output {
            width: 1280,
            height: 720,
            background: [0, 0, 0, 255],
        },
        camera: Camera {
            eye: Vec3::new(0.0, 1.0, 0.0),
            target: Vec3::new(0.0, 0.75, -10.0),
            up: Vec3::Y,
            fovy_deg: 50.0,
            near: 0.05,
            far: 2000.0,
        },
        textures: white_texture(),
        meshes: vec![mirror_plane_mesh()],
        lights: Vec::new(),
        materials: [(
            "mirror".to_string(),
            metal(Vec3::new(0.95, 0.93, 0.88), 0.0),
        )]
        .into(),
        environment: sky_environment(2048),
    }
}

/// Radius of the knot's tube ([`knot_mesh`]).
pub const KNOT_RADIUS: f32 = 0.2;

/// Segments along the built-in knot's tube and around it ([`knot_mesh`]): 25 600 triangles.
pub const KNOT_SEGMENTS: (u32, u32) = (400, 32);

/// A (2, 3) torus knot tube resting on a square of ground, as one mesh whose uvs form a
/// non-overlapping atlas (for baking: every surface point has its own texel):
/// - the tube: the centre line `c(t) = 0.5 ((2 + cos 3t) cos 2t, -sin 3t, (2 + cos 3t) sin 2t)`
///   lifted so its lowest point touches `y = 0`, radius [`KNOT_RADIUS`], `segments` steps along it and
///   `sides` around; its first half maps to `u` in `[0.01, 0.99]`, `v` in `[0.01, 0.24]` and its
///   second half to `v` in `[0.26, 0.49]` (`u` along, `v` around: about as many texels per unit
///   along as around);
/// - the ground: a 4.5 x 4.5 square at `y = 0` under it, `uv` in `[0.26, 0.74] x [0.51, 0.99]`.
///
/// Triangles are counter-clockwise from outside; the tube has smooth normals (the tube frame
/// holds `+y` as its reference, which the tangent never meets: the centre line's horizontal speed
/// is at least 1). `segments` is rounded up to an even number, at least 4; `sides` at least 3.
pub fn knot_mesh(segments: u32, sides: u32) -> Mesh {
    let segments = segments.max(4).next_multiple_of(2);
    let sides = sides.max(3);
    let centre = |t: f32| {
        let r = 2.0 + (3.0 * t).cos();
        Vec3::new(r * (2.0 * t).cos(), -(3.0 * t).sin(), r * (2.0 * t).sin()) * 0.5
    };
    let radius = KNOT_RADIUS;
    let lift = Vec3::new(0.0, 0.5 + radius, 0.0);
    let mut mesh = Mesh {
        material: Some("clay".into()),
        ..empty_mesh("clay")
    };
    let half = segments / 2;
    for strip in 0..2u32 {
        let base = mesh.positions.len() as u32;
        for i in 0..=half {
            let t = 2.0 * PI * (strip * half + i) as f32 / segments as f32;
            let h = 1e-3;
            let tangent = (centre(t + h) - centre(t - h)).normalize();
            let side = tangent.cross(Vec3::Y).normalize();
            let up = side.cross(tangent);
            for j in 0..=sides {
                let a = 2.0 * PI * j as f32 / sides as f32;
                let n = side * a.cos() + up * a.sin();
                mesh.positions.push(centre(t) + lift + n * radius);
                if let Some(ns) = &mut mesh.normals {
                    ns.push(n);
                }
                mesh.uvs.push(Vec2::new(
                    0.01 + 0.98 * i as f32 / half as f32,
                    0.01 + 0.25 * strip as f32 + 0.23 * j as f32 / sides as f32,
                ));
            }
        }
        let row = sides + 1;
        for i in 0..half {
            for j in 0..sides {
                let a = base + i * row + j;
                let b = a + row;
                mesh.triangles.extend([[a, b, b + 1], [a, b + 1, a + 1]]);
            }
        }
    }
    let base = mesh.positions.len() as u32;
    for (x, z, uv) in [
        (-2.25, -2.25, Vec2::new(0.26, 0.51)),
        (-2.25, 2.25, Vec2::new(0.26, 0.99)),
        (2.25, 2.25, Vec2::new(0.74, 0.99)),
        (2.25, -2.25, Vec2::new(0.74, 0.51)),
    ] {
        mesh.positions.push(Vec3::new(x, 0.0, z));
        mesh.uvs.push(uv);
        if let Some(ns) = &mut mesh.normals {
            ns.push(Vec3::Y);
        }
    }
    mesh.triangles
        .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    mesh
}

/// The `knot` scene: [`knot_mesh`] at [`KNOT_SEGMENTS`], a clay material, a sky-blue ambient
/// light and a sun from the upper left.
fn knot() -> Scene {
    let (segments, sides) = KNOT_SEGMENTS;
    let clay = crate::model::MaterialSpec {
        base_color: crate::model::ColorInput::Rgb(Vec3::new(0.8, 0.72, 0.62)),
        roughness: crate::model::ScalarInput::Value(0.7),
        ..Default::default()
    };
    Scene {
        output: Output {
            width: 960,
            height: 540,
            background: [180, 200, 225, 255],
        },
        camera: Camera {
            eye: Vec3::new(0.0, 3.6, 4.6),
            target: Vec3::new(0.0, 0.45, 0.0),
            up: Vec3::Y,
            fovy_deg: 40.0,
            near: 0.1,
            far: 100.0,
        },
        textures: [(
            "clay".to_string(),
            TextureSpec::new(
                TextureSource::Procedural(Procedural::Solid {
                    width: 4,
                    height: 4,
                    rgba: [255, 255, 255, 255],
                }),
                ColorSpace::Srgb,
            ),
        )]
        .into(),
        meshes: vec![knot_mesh(segments, sides)],
        lights: vec![
            crate::model::LightSpec::Ambient {
                intensity: Vec3::new(0.5, 0.55, 0.65),
            },
            crate::model::LightSpec::Directional {
                direction: Vec3::new(-0.5, 1.0, 0.3),
                intensity: Vec3::new(1.3, 1.2, 1.1),
            },
        ],
        materials: [("clay".to_string(), clay)].into(),
        environment: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_loads_and_validates() {
        for name in builtin_names().iter().chain(shaded_builtin_names()) {
            let s = Scene::load(&format!("builtin:{name}")).unwrap();
            s.validate().unwrap();
            assert!(!s.meshes.is_empty(), "{name}");
        }
        let e = Scene::load("builtin:nope").unwrap_err();
        assert!(e.to_string().contains("ground-rotated"), "{e}");
    }

    /// Signed volume of a closed mesh: positive when every triangle is counter-clockwise from
    /// outside (divergence theorem).
    fn volume(m: &Mesh) -> f32 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn cube_and_sphere_are_closed_and_outward() {
        let c = cube();
        assert!((volume(&c.meshes[0]) - 8.0).abs() < 1e-4);
        let s = sphere();
        let v = volume(&s.meshes[0]);
        // A 64 x 32 UV sphere has a little less volume than 4/3 pi.
        assert!(v > 4.0 && v < 4.0 / 3.0 * PI, "{v}");
        // Each triangle faces outwards: its normal agrees with its centroid direction.
        for m in [&c.meshes[0], &s.meshes[0]] {
            for t in &m.triangles {
                let [a, b, cc] = t.map(|i| m.positions[i as usize]);
                assert!((b - a).cross(cc - a).dot(a + b + cc) > 0.0);
            }
        }
        // Cube face uvs: the +z face's top-left corner (-1, 1, 1) has uv (0, 0).
        let m = &c.meshes[0];
        let i = m
            .positions
            .iter()
            .zip(&m.normals.as_ref().unwrap()[..])
            .position(|(p, n)| *p == Vec3::new(-1.0, 1.0, 1.0) && *n == Vec3::Z)
            .unwrap();
        assert_eq!(m.uvs[i], Vec2::ZERO);
    }

    #[test]
    fn knot_is_outward_and_does_not_touch_itself() {
        let m = knot_mesh(200, 16);
        assert_eq!(m.triangles.len(), 200 * 16 * 2 + 2);
        assert_eq!(m.uvs.len(), m.positions.len());
        let normals = m.normals.as_ref().unwrap();
        // Each triangle faces the way its vertices' normals point.
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n: Vec3 = t.iter().map(|&i| normals[i as usize]).sum();
            assert!((b - a).cross(c - a).dot(n) > 0.0, "{t:?}");
        }
        // It rests on the ground: its lowest point is at y = 0 (to the ring's sampling).
        let low = m
            .positions
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        assert!(low.abs() < 1e-3, "{low}");
        // Strands more than a tube's width apart along the knot stay more than a diameter apart
        // (centre line: vertex rings' means).
        let rings: Vec<Vec3> = m.positions[..(101 * 17)]
            .chunks(17)
            .chain(m.positions[101 * 17..2 * 101 * 17].chunks(17))
            .map(|r| r[..16].iter().sum::<Vec3>() / 16.0)
            .collect();
        for (i, a) in rings.iter().enumerate() {
            for (j, b) in rings.iter().enumerate() {
                let along = (i as i32 - j as i32)
                    .rem_euclid(202)
                    .min((j as i32 - i as i32).rem_euclid(202));
                if along > 20 {
                    assert!(
                        a.distance(*b) > 2.0 * KNOT_RADIUS,
                        "{i} {j} {}",
                        a.distance(*b)
                    );
                }
            }
        }
        // The uv islands lie inside the map and do not overlap: the tube's two strips and the
        // ground are in separate rectangles.
        assert!(m
            .uvs
            .iter()
            .all(|uv| uv.min_element() > 0.0 && uv.max_element() < 1.0));
    }

    #[test]
    fn rotated_ground_turns_uvs_by_30_degrees() {
        let g = builtin("ground").unwrap();
        let r = builtin("ground-rotated").unwrap();
        for (a, b) in g.meshes[0].uvs.iter().zip(&r.meshes[0].uvs) {
            assert!((a.length() - b.length()).abs() < 1e-3 * a.length().max(1.0));
            if a.length() > 1.0 {
                let angle = a.angle_to(*b).to_degrees();
                assert!((angle - 30.0).abs() < 1e-3, "{angle}");
            }
        }
        assert_eq!(g.meshes[0].positions, r.meshes[0].positions);
    }
}
