//! glTF 2.0 meshes (`.gltf` with embedded or external buffers, or binary `.glb`) through the
//! `gltf` crate.
//!
//! The default scene (else the first; else every mesh untransformed) is walked from its root nodes;
//! each node's local transform is composed with its parent's, and every primitive becomes one
//! [`Mesh`] with world-space positions (normals by the inverse transpose, renormalised).
//! `POSITION` and `TEXCOORD_0` are required; `NORMAL`, `TANGENT` (its `xyz` by the node's
//! transform, `w` flipped where the transform mirrors) and `COLOR_0` are kept when present; without
//! `indices` the vertices are taken in order. `TRIANGLES`, `TRIANGLE_STRIP` and `TRIANGLE_FAN`
//! are turned into triangle lists (glTF 2.0 spec 3.7.2.1); points and lines are an error.
//!
//! The base colour texture's sampler gives the address modes (`wrapS`/`wrapT`: `REPEAT` ->
//! Repeat, `MIRRORED_REPEAT` -> MirrorRepeat, `CLAMP_TO_EDGE` -> ClampToEdge; glTF's default is
//! Repeat) and the filters ([`MeshFilters`]). [`load_gltf`] reads geometry only (the scene file
//! names the texture); [`import_gltf`] also imports the file's `pbrMetallicRoughness` materials
//! and their images (files beside the glTF, `data:` URIs or buffer views), each texture with its
//! own sampler.
//!
//! Hostile files are refused before they cost anything ([`SceneLimits`]): the node hierarchy must
//! be disjoint trees as glTF 2.0 requires (a node with two parents, a cycle, or a scene root that
//! is another node's child would instantiate shared subtrees exponentially often); the instances'
//! triangles and vertices are counted from accessor counts before any is read; buffers are read
//! here, not by `gltf::import_buffers`: at most `byteLength` bytes each, from the GLB binary chunk,
//! a base64 `data:` URI or a regular file beside the glTF (absolute paths and `file:` URIs are
//! allowed, other schemes are not), and their `byteLength`s together within the file bound.
//! Accessors outside their buffers read as missing and are reported.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;
use gltf::texture::{MagFilter, MinFilter, WrappingMode};
use texel_texture::{AddressMode, ColorSpace, FilterMode, MipmapFilterMode};

use crate::error::SceneError;
use crate::limits::SceneLimits;
use crate::model::{
    ColorInput, EncodedImage, MaterialSpec, Mesh, MeshFilters, ScalarInput, TextureSampler,
    TextureSource, TextureSpec,
};
use crate::procedural::Procedural;

fn wrap(m: WrappingMode) -> AddressMode {
    match m {
        WrappingMode::ClampToEdge => AddressMode::ClampToEdge,
        WrappingMode::MirroredRepeat => AddressMode::MirrorRepeat,
        WrappingMode::Repeat => AddressMode::Repeat,
    }
}

/// The [`MeshFilters`] for a glTF sampler's `magFilter` and `minFilter`.
pub(crate) fn filters(mag: Option<MagFilter>, min: Option<MinFilter>) -> MeshFilters {
    use FilterMode::{Linear, Nearest};
    let (min_filter, mipmap_filter) = match min {
        None => (None, None),
        Some(MinFilter::Nearest) => (Some(Nearest), Some(MipmapFilterMode::None)),
        Some(MinFilter::Linear) => (Some(Linear), Some(MipmapFilterMode::None)),
        Some(MinFilter::NearestMipmapNearest) => (Some(Nearest), Some(MipmapFilterMode::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Some(Linear), Some(MipmapFilterMode::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Some(Nearest), Some(MipmapFilterMode::Linear)),
        Some(MinFilter::LinearMipmapLinear) => (Some(Linear), Some(MipmapFilterMode::Linear)),
    };
    MeshFilters {
        mag_filter: mag.map(|m| match m {
            MagFilter::Nearest => Nearest,
            MagFilter::Linear => Linear,
        }),
        min_filter,
        mipmap_filter,
    }
}

/// How a node's transform places a mesh: points by `world`, tangents by its linear part `linear`,
/// normals by `normal_from_world` (the inverse transpose), a tangent's `w` times `flip`.
#[derive(Clone, Copy)]
struct Placement {
    world: Mat4,
    linear: Mat3,
    normal_from_world: Mat3,
    flip: f32,
}

impl Placement {
    /// The placement by transform `world`.
    fn new(world: Mat4) -> Self {
        let linear = Mat3::from_mat4(world);
        let normal_from_world = linear.inverse().transpose();
        // A mirroring transform flips the bitangent: a tangent's w follows the determinant's sign.
        let flip = linear.determinant().signum();
        Placement {
            world,
            linear,
            normal_from_world,
            flip,
        }
    }
}

/// The address modes and filters of base colour texture `base_info`'s sampler; Repeat and no
/// filters without one.
fn sampler_modes(
    base_info: Option<&gltf::texture::Info>,
) -> (AddressMode, AddressMode, Option<MeshFilters>) {
    let sampler = base_info.map(|info| info.texture().sampler());
    match &sampler {
        Some(s) => (
            wrap(s.wrap_s()),
            wrap(s.wrap_t()),
            Some(filters(s.mag_filter(), s.min_filter())),
        ),
        None => (AddressMode::Repeat, AddressMode::Repeat, None),
    }
}

/// The triangle list a primitive of `mode` makes from `indices` (glTF 2.0 spec 3.7.2.1); `None`
/// for points and lines.
fn triangle_list(mode: Mode, indices: &[u32]) -> Option<Vec<[u32; 3]>> {
    Some(match mode {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [indices[i], indices[i + 1], indices[i + 2]]
                } else {
                    [indices[i + 1], indices[i], indices[i + 2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..indices.len().saturating_sub(1))
            .map(|i| [indices[0], indices[i], indices[i + 1]])
            .collect(),
        _ => return None,
    })
}

/// Deepest node nesting followed (the recursion's stack depth).
const MAX_DEPTH: usize = 256;

struct Ctx<'a> {
    path: &'a Path,
    /// The scene's `texture` for every mesh, or `None` to take each primitive's base colour
    /// texture (when importing).
    texture: Option<&'a str>,
    /// Prefix of imported names (`"FILE#"`); empty where materials are not imported (the scene
    /// names one).
    prefix: &'a str,
    base: Option<&'a Path>,
    buffers: &'a [Vec<u8>],
    limits: &'a SceneLimits,
    out: Vec<Mesh>,
    textures: BTreeMap<String, TextureSpec>,
    materials: BTreeMap<String, MaterialSpec>,
    /// Each glTF image read so far, by index: the textures that name one image share its source
    /// (one copy of its bytes, one decode when the scene is prepared).
    images: BTreeMap<usize, TextureSource>,
}

impl Ctx<'_> {
    /// Whether the file's materials are imported.
    fn importing(&self) -> bool {
        !self.prefix.is_empty()
    }

    fn bad(&self, reason: String) -> SceneError {
        SceneError::MeshFile {
            path: self.path.to_path_buf(),
            reason,
        }
    }

    fn node(&mut self, node: gltf::Node, parent: Mat4, depth: usize) -> Result<(), SceneError> {
        if depth > MAX_DEPTH {
            return Err(self.bad(format!(
                "node hierarchy deeper than {MAX_DEPTH} at node {}",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, world)?;
        }
        for child in node.children() {
            self.node(child, world, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), SceneError> {
        let placement = Placement::new(world);
        for (pi, prim) in mesh.primitives().enumerate() {
            let what = format!("mesh {} primitive {pi}", mesh.index());
            if let Some(m) = self.primitive(&prim, &what, &placement)? {
                self.out.push(m);
            }
        }
        Ok(())
    }

    /// Reads primitive `prim` (named `what` in errors) as a mesh placed by `placement`, with its
    /// sampler's address modes and filters, its material and its texture; `None` where it has
    /// no triangles.
    fn primitive(
        &mut self,
        prim: &gltf::Primitive,
        what: &str,
        placement: &Placement,
    ) -> Result<Option<Mesh>, SceneError> {
        let Placement {
            world,
            linear,
            normal_from_world,
            flip,
        } = *placement;
        let buffers = self.buffers;
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| self.bad(format!("{what}: no readable POSITION")))?
            .map(|p| world.transform_point3(Vec3::from(p)))
            .collect();
        let uvs: Vec<Vec2> = reader
            .read_tex_coords(0)
            .ok_or_else(|| self.bad(format!("{what}: no readable TEXCOORD_0 (texel needs uvs)")))?
            .into_f32()
            .map(Vec2::from)
            .collect();
        let normals = reader.read_normals().map(|it| {
            it.map(|n| (normal_from_world * Vec3::from(n)).normalize_or_zero())
                .collect::<Vec<_>>()
        });
        let colors = reader
            .read_colors(0)
            .map(|c| c.into_rgba_f32().map(Vec4::from).collect::<Vec<_>>());
        let n = positions.len() as u32;
        let indices: Vec<u32> = match prim.indices() {
            Some(_) => reader
                .read_indices()
                .ok_or_else(|| self.bad(format!("{what}: indices outside their buffer")))?
                .into_u32()
                .collect(),
            None => (0..n).collect(),
        };
        let triangles = triangle_list(prim.mode(), &indices).ok_or_else(|| {
            self.bad(format!(
                "{what}: mode {:?} has no triangles to texture",
                prim.mode()
            ))
        })?;
        let tangents = reader.read_tangents().map(|it| {
            it.map(|t| {
                let xyz = (linear * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                xyz.extend(if t[3] < 0.0 { -flip } else { flip })
            })
            .collect::<Vec<_>>()
        });
        let material = prim.material();
        let base_info = material.pbr_metallic_roughness().base_color_texture();
        let (address_mode_u, address_mode_v, filters) = sampler_modes(base_info.as_ref());
        if triangles.is_empty() {
            // Nothing to draw (glTF allows it); the file is refused only if nothing is left.
            return Ok(None);
        }
        let imported = match material.index() {
            Some(index) if self.importing() => Some(self.material(&material, index)?),
            _ => None,
        };
        let texture = self.primitive_texture(base_info)?;
        Ok(Some(Mesh {
            positions,
            uvs,
            normals,
            colors,
            triangles,
            texture,
            address_mode_u,
            address_mode_v,
            filters,
            material: imported,
            tangents,
            uv_mapping: None,
        }))
    }

    /// The texture a primitive is drawn with: the scene's, else (when importing) its base colour
    /// texture `base_info`, else white.
    fn primitive_texture(
        &mut self,
        base_info: Option<gltf::texture::Info>,
    ) -> Result<String, SceneError> {
        Ok(match (self.texture, base_info) {
            (Some(t), _) => t.to_string(),
            (None, Some(info)) if self.importing() => self.texture(
                &info.texture(),
                info.tex_coord(),
                ColorSpace::Srgb,
                "baseColorTexture",
            )?,
            (None, _) => self.white(),
        })
    }

    /// The scene material of glTF material `m` (number `index`), imported on first use: its
    /// `pbrMetallicRoughness` base colour factor (the base colour texture is the mesh's own),
    /// roughness and metalness (factors times the green and blue of `metallicRoughnessTexture`),
    /// normal texture and scale, occlusion texture and strength.
    fn material(&mut self, m: &gltf::Material, index: usize) -> Result<String, SceneError> {
        let name = format!("{}material{index}", self.prefix);
        if self.materials.contains_key(&name) {
            return Ok(name);
        }
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let mut spec = MaterialSpec {
            base_color: ColorInput::Rgb(Vec3::new(r, g, b)),
            roughness: ScalarInput::Value(pbr.roughness_factor()),
            metallic: ScalarInput::Value(pbr.metallic_factor()),
            ..MaterialSpec::default()
        };
        let what = |key: &str| format!("material {index}: {key}");
        if let Some(info) = pbr.metallic_roughness_texture() {
            let t = self.texture(
                &info.texture(),
                info.tex_coord(),
                ColorSpace::Linear,
                &what("metallicRoughnessTexture"),
            )?;
            spec.roughness = ScalarInput::Channel {
                texture: t.clone(),
                channel: 1,
                factor: pbr.roughness_factor(),
            };
            spec.metallic = ScalarInput::Channel {
                texture: t,
                channel: 2,
                factor: pbr.metallic_factor(),
            };
        }
        if let Some(n) = m.normal_texture() {
            let t = &n.texture();
            spec.normal =
                Some(self.texture(t, n.tex_coord(), ColorSpace::Linear, &what("normalTexture"))?);
            spec.normal_scale = n.scale();
        }
        if let Some(o) = m.occlusion_texture() {
            let t = &o.texture();
            spec.occlusion = Some(self.texture(
                t,
                o.tex_coord(),
                ColorSpace::Linear,
                &what("occlusionTexture"),
            )?);
            spec.occlusion_strength = o.strength();
        }
        self.materials.insert(name.clone(), spec);
        Ok(name)
    }

    /// The scene texture of glTF texture `t` read as `color` (base colours sRGB, data linear),
    /// with its sampler, added on first use. Only `TEXCOORD_0` is read (`tex_coord` must be 0).
    fn texture(
        &mut self,
        t: &gltf::Texture,
        tex_coord: u32,
        color: ColorSpace,
        what: &str,
    ) -> Result<String, SceneError> {
        if tex_coord != 0 {
            return Err(self.bad(format!(
                "{what} reads TEXCOORD_{tex_coord}; texel reads one uv set, TEXCOORD_0"
            )));
        }
        let space = match color {
            ColorSpace::Srgb => "srgb",
            ColorSpace::Linear => "linear",
        };
        let name = format!("{}texture{}.{space}", self.prefix, t.index());
        if !self.textures.contains_key(&name) {
            let image = t.source();
            let source = match self.images.get(&image.index()) {
                Some(source) => source.clone(),
                None => {
                    let source = self.image(&image)?;
                    self.images.insert(image.index(), source.clone());
                    source
                }
            };
            let s = t.sampler();
            let sampler = TextureSampler {
                address_mode_u: wrap(s.wrap_s()),
                address_mode_v: wrap(s.wrap_t()),
                filters: filters(s.mag_filter(), s.min_filter()),
            };
            let spec = TextureSpec {
                sampler: Some(sampler),
                ..TextureSpec::new(source, color)
            };
            self.textures.insert(name.clone(), spec);
        }
        Ok(name)
    }

    /// Where glTF image `image`'s bytes are: a buffer view (GLB or embedded buffers), a base64
    /// `data:` URI, or a file beside the glTF (as buffers are found). Read once per image
    /// ([`Ctx::texture`] keeps what it returns).
    fn image(&self, image: &gltf::Image) -> Result<TextureSource, SceneError> {
        let i = image.index();
        let origin = format!("{}, image {i}", self.path.display());
        let bytes: Vec<u8> = match image.source() {
            gltf::image::Source::View { view, .. } => {
                // A buffer holds its byteLength bytes (padded to 4 after them, not readable).
                let buffer = view.buffer();
                let (start, end) = (view.offset(), view.offset().saturating_add(view.length()));
                let bytes = self
                    .buffers
                    .get(buffer.index())
                    .and_then(|d| d.get(..buffer.length())?.get(start..end));
                bytes
                    .ok_or_else(|| {
                        self.bad(format!(
                            "image {i}: buffer view bytes {start}..{end} lie outside buffer {} \
                             ({} bytes)",
                            buffer.index(),
                            buffer.length()
                        ))
                    })?
                    .to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => match uri.strip_prefix("data:") {
                Some(rest) => decode_data_uri(rest, self.limits.max_mesh_file_bytes)
                    .map_err(|e| self.bad(format!("image {i}: {e}")))?,
                None => {
                    let path = buffer_path(uri, self.base)
                        .map_err(|e| self.bad(format!("image {i}: {e}")))?;
                    return Ok(TextureSource::File(path));
                }
            },
        };
        Ok(TextureSource::Encoded(EncodedImage {
            bytes: bytes.into(),
            origin,
        }))
    }

    /// A 1 x 1 white texture for meshes with no base colour texture and none named.
    fn white(&mut self) -> String {
        let name = format!("{}white", self.prefix);
        self.textures.entry(name.clone()).or_insert_with(|| {
            TextureSpec::new(
                TextureSource::Procedural(Procedural::Solid {
                    width: 1,
                    height: 1,
                    rgba: [255; 4],
                }),
                ColorSpace::Srgb,
            )
        });
        name
    }
}

/// The bytes of a base64 `data:` URI's payload (`rest` is what follows `data:`), at most
/// `max_bytes` of them.
fn decode_data_uri(rest: &str, max_bytes: u64) -> Result<Vec<u8>, String> {
    let b64 = rest
        .split_once(";base64,")
        .map(|(_, d)| d)
        .ok_or("a data URI that is not base64")?;
    if b64.len() as u64 / 4 * 3 > max_bytes {
        return Err(format!(
            "a data URI of {} base64 characters, over the limit of {max_bytes} bytes",
            b64.len()
        ));
    }
    use base64::Engine;
    base64::engine::general_purpose::STANDARD
        .decode(b64.trim_end())
        .map_err(|e| format!("invalid base64 data URI: {e}"))
}

/// Triangles a primitive of `mode` makes from `n` indices (glTF 2.0 spec 3.7.2.1).
fn triangle_count(mode: Mode, n: u64) -> Option<u64> {
    match mode {
        Mode::Triangles => Some(n / 3),
        Mode::TriangleStrip | Mode::TriangleFan => Some(n.saturating_sub(2)),
        _ => None,
    }
}

/// Check that the nodes form disjoint trees: every node has at most one parent, no node is its
/// own ancestor, and a scene's root nodes are nobody's children.
fn check_hierarchy(document: &gltf::Document) -> Result<(), String> {
    let n = document.nodes().len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for node in document.nodes() {
        for child in node.children() {
            let c = child.index();
            if let Some(p) = parent[c] {
                return Err(format!(
                    "node {c} is a child of both node {p} and node {}: glTF 2.0 node hierarchies must be disjoint trees",
                    node.index()
                ));
            }
            parent[c] = Some(node.index());
        }
    }
    // With one parent each, a cycle is a chain of parents that comes back on itself. Each node is
    // walked over once: a walk stops at a node an earlier walk already cleared.
    let mut state = vec![0u8; n]; // 0 unvisited, 1 on the current walk, 2 cleared
    for start in 0..n {
        let mut at = start;
        while state[at] == 0 {
            state[at] = 1;
            match parent[at] {
                Some(p) => at = p,
                None => break,
            }
        }
        if state[at] == 1 && parent[at].is_some() {
            return Err(format!("node {at} is its own ancestor (a cycle)"));
        }
        let mut at = start;
        while state[at] == 1 {
            state[at] = 2;
            match parent[at] {
                Some(p) => at = p,
                None => break,
            }
        }
    }
    for scene in document.scenes() {
        for root in scene.nodes() {
            if let Some(p) = parent[root.index()] {
                return Err(format!(
                    "node {} is a root of scene {} but also a child of node {p}",
                    root.index(),
                    scene.index()
                ));
            }
        }
    }
    Ok(())
}

/// Check what the gltf crate's readers assume and do not check (its readers hit `unreachable!`
/// on other types): POSITION and NORMAL `VEC3` floats, TANGENT `VEC4` floats, TEXCOORD_0 `VEC2` of floats or normalised
/// u8/u16, COLOR_0 `VEC3`/`VEC4` of those, indices scalar u8/u16/u32; every attribute with as many
/// elements as POSITION (glTF 2.0 3.7.2.1), and at most `3 * max_triangles + 2` indices (read
/// before the mode is looked at). Counts are checked here, before a sparse accessor of billions
/// of elements is expanded.
fn check_primitive(prim: &gltf::Primitive, limits: &SceneLimits) -> Result<(), String> {
    use gltf::accessor::{DataType as T, Dimensions as D};
    use gltf::Semantic;
    let n = prim
        .get(&Semantic::Positions)
        .map_or(0, |a| a.count() as u64);
    for (semantic, a) in prim.attributes() {
        let ok = match &semantic {
            Semantic::Positions | Semantic::Normals => {
                (a.data_type(), a.dimensions()) == (T::F32, D::Vec3)
            }
            Semantic::Tangents => (a.data_type(), a.dimensions()) == (T::F32, D::Vec4),
            Semantic::TexCoords(_) => {
                matches!(a.data_type(), T::F32 | T::U8 | T::U16) && a.dimensions() == D::Vec2
            }
            Semantic::Colors(_) => {
                matches!(a.data_type(), T::F32 | T::U8 | T::U16)
                    && matches!(a.dimensions(), D::Vec3 | D::Vec4)
            }
            _ => true,
        };
        if !ok {
            return Err(format!(
                "attribute {semantic:?} is {:?} {:?}, which glTF 2.0 does not allow for it",
                a.data_type(),
                a.dimensions()
            ));
        }
        if a.count() as u64 != n {
            return Err(format!(
                "attribute {semantic:?} has {} elements but POSITION has {n}",
                a.count()
            ));
        }
    }
    if let Some(a) = prim.indices() {
        if !matches!(a.data_type(), T::U8 | T::U16 | T::U32) || a.dimensions() != D::Scalar {
            return Err(format!(
                "indices are {:?} {:?}; glTF 2.0 needs scalar u8, u16 or u32",
                a.data_type(),
                a.dimensions()
            ));
        }
        let max = limits.max_triangles.saturating_mul(3).saturating_add(2);
        if a.count() as u64 > max {
            return Err(format!(
                "{} indices, over the {max} that {} triangles can use",
                a.count(),
                limits.max_triangles
            ));
        }
    }
    Ok(())
}

/// Check every accessor's layout against glTF 2.0 (3.6.2, 5.1, 5.11) before the gltf crate's
/// readers slice buffers with it (they index without checks and panic): its buffer view and the
/// view's buffer exist, the view lies inside its buffer, a `byteStride` is 4 to 252, a multiple of
/// the component size and at least the element's size, the accessor's offset is aligned to its
/// component, its last element ends inside the view, and a sparse accessor's indices (u8, u16 or
/// u32) and values fit their views, which declare no stride.
fn check_accessors(json: &gltf::json::Root) -> Result<(), String> {
    for (i, a) in json.accessors.iter().enumerate() {
        check_accessor(json, i, a)?;
    }
    Ok(())
}

/// Checks accessor `i` (`a`): known component and element types, at least one element, its
/// layout in its buffer view, and its sparse part.
fn check_accessor(
    json: &gltf::json::Root,
    i: usize,
    a: &gltf::json::Accessor,
) -> Result<(), String> {
    use gltf::json::validation::Checked;
    let what = format!("accessor {i}");
    let (Checked::Valid(ct), Checked::Valid(ty)) = (&a.component_type, &a.type_) else {
        return Err(format!(
            "{what} has an unknown component type or element type"
        ));
    };
    let comp = ct.0.size() as u64;
    let elem = comp * ty.multiplicity() as u64;
    let count = a.count.0;
    if count == 0 {
        // glTF 2.0 requires count >= 1 (the crate's readers compute count - 1).
        return Err(format!(
            "{what} has no elements (glTF 2.0 needs a count of at least 1)"
        ));
    }
    let offset = a.byte_offset.map_or(0, |o| o.0);
    if let Some(v) = &a.buffer_view {
        check_accessor_view(json, &what, v.value(), offset, count, comp, elem)?;
    }
    if let Some(sp) = &a.sparse {
        check_sparse(json, &what, sp, count, elem)?;
    }
    Ok(())
}

/// Checks that accessor `what`'s `count` elements of `elem` bytes (`comp`-byte components),
/// from `offset` in buffer view `v`, are aligned, have an allowed stride and lie inside the view.
fn check_accessor_view(
    json: &gltf::json::Root,
    what: &str,
    v: usize,
    offset: u64,
    count: u64,
    comp: u64,
    elem: u64,
) -> Result<(), String> {
    let (len, stride) = view_at(json, v, what)?;
    if !offset.is_multiple_of(comp) {
        return Err(format!(
            "{what}'s byteOffset {offset} is not a multiple of its component size {comp}"
        ));
    }
    if let Some(s) = stride {
        if !(4..=252).contains(&s) || s % comp != 0 || s < elem {
            return Err(format!(
                "{what} reads buffer view {v} with byteStride {s}, but its elements are {elem} bytes of {comp}-byte components (glTF 2.0 needs a stride of 4 to 252, a multiple of {comp}, at least {elem})"
            ));
        }
    }
    if !fits(offset, count, stride.unwrap_or(elem), elem, len) {
        return Err(format!(
            "{what}'s {count} elements of {elem} bytes from offset {offset} reach past the end of buffer view {v} ({len} bytes)"
        ));
    }
    Ok(())
}

/// Checks the sparse part `sp` of accessor `what` (`count` elements of `elem` bytes): at least one
/// and at most `count` elements, indices u8, u16 or u32, and indices and values inside their
/// views, which declare no stride.
fn check_sparse(
    json: &gltf::json::Root,
    what: &str,
    sp: &gltf::json::accessor::sparse::Sparse,
    count: u64,
    elem: u64,
) -> Result<(), String> {
    use gltf::json::accessor::ComponentType as C;
    use gltf::json::validation::Checked;
    let n = sp.count.0;
    if n == 0 {
        return Err(format!(
            "{what} is sparse with no elements (glTF 2.0 needs a count of at least 1)"
        ));
    }
    if n > count {
        return Err(format!(
            "{what} has {n} sparse elements but only {count} elements"
        ));
    }
    let Checked::Valid(it) = &sp.indices.component_type else {
        return Err(format!(
            "{what}'s sparse indices have an unknown component type"
        ));
    };
    if !matches!(it.0, C::U8 | C::U16 | C::U32) {
        return Err(format!("{what}'s sparse indices are not u8, u16 or u32"));
    }
    let parts = [
        (
            "indices",
            sp.indices.buffer_view.value(),
            sp.indices.byte_offset.0,
            it.0.size() as u64,
        ),
        (
            "values",
            sp.values.buffer_view.value(),
            sp.values.byte_offset.0,
            elem,
        ),
    ];
    for (part, v, off, size) in parts {
        let (len, stride) = view_at(json, v, what)?;
        if stride.is_some() {
            return Err(format!(
                "{what}'s sparse {part} use buffer view {v}, which declares a byteStride"
            ));
        }
        if !fits(off, n, size, size, len) {
            return Err(format!(
                "{what}'s {n} sparse {part} from offset {off} reach past the end of buffer view {v} ({len} bytes)"
            ));
        }
    }
    Ok(())
}

/// The length and stride (`None` where undeclared or zero) of buffer view `v`, which `what`
/// refers to, after checking that it and its buffer exist and that it lies inside the buffer.
fn view_at(json: &gltf::json::Root, v: usize, what: &str) -> Result<(u64, Option<u64>), String> {
    let view = json.buffer_views.get(v).ok_or_else(|| {
        format!(
            "{what} refers to buffer view {v}, but the file has {}",
            json.buffer_views.len()
        )
    })?;
    let b = view.buffer.value();
    let buffer = json.buffers.get(b).ok_or_else(|| {
        format!(
            "buffer view {v} refers to buffer {b}, but the file has {}",
            json.buffers.len()
        )
    })?;
    let offset = view.byte_offset.map_or(0, |o| o.0);
    let len = view.byte_length.0;
    if offset
        .checked_add(len)
        .is_none_or(|end| end > buffer.byte_length.0)
    {
        return Err(format!(
            "buffer view {v} (offset {offset}, {len} bytes) reaches past the end of buffer {b} ({} bytes)",
            buffer.byte_length.0
        ));
    }
    let stride = view.byte_stride.map(|s| s.0 as u64).filter(|&s| s != 0);
    Ok((len, stride))
}

/// Whether `count` elements of `elem` bytes, `stride` apart, from `offset` fit in `len` bytes.
fn fits(offset: u64, count: u64, stride: u64, elem: u64, len: u64) -> bool {
    count == 0
        || (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(offset))
            .and_then(|x| x.checked_add(elem))
            .is_some_and(|end| end <= len)
}

/// The triangles and vertices of `mesh`'s primitives, from accessor counts (nothing is read).
fn mesh_counts(mesh: &gltf::Mesh) -> (u64, u64) {
    let (mut tris, mut verts) = (0u64, 0u64);
    for prim in mesh.primitives() {
        let v = prim
            .get(&gltf::Semantic::Positions)
            .map_or(0, |a| a.count() as u64);
        let i = prim.indices().map_or(v, |a| a.count() as u64);
        tris = tris.saturating_add(triangle_count(prim.mode(), i).unwrap_or(0));
        verts = verts.saturating_add(v);
    }
    (tris, verts)
}

/// Read buffer `buffer`: exactly its `byteLength` bytes (padded to a multiple of 4, as the gltf
/// crate's readers expect).
fn read_buffer(
    buffer: &gltf::Buffer,
    base: Option<&Path>,
    blob: Option<&[u8]>,
) -> Result<Vec<u8>, String> {
    let len = buffer.length();
    let i = buffer.index();
    let mut data = match buffer.source() {
        gltf::buffer::Source::Bin => {
            let blob = blob.ok_or(format!(
                "buffer {i} refers to a GLB binary chunk the file does not have"
            ))?;
            blob.get(..len)
                .ok_or(format!(
                    "buffer {i}: byteLength {len} but the GLB binary chunk has {} bytes",
                    blob.len()
                ))?
                .to_vec()
        }
        gltf::buffer::Source::Uri(uri) => {
            if let Some(rest) = uri.strip_prefix("data:") {
                // byteLength bounds the payload (a base64 quad carries 3 bytes).
                decode_data_uri(rest, (len as u64 / 3 + 1) * 3)
                    .map_err(|e| format!("buffer {i}: {e}"))?
            } else {
                let path = buffer_path(uri, base).map_err(|e| format!("buffer {i}: {e}"))?;
                let file = texel_io::open_regular(&path)
                    .map_err(|e| format!("buffer {i}: {}: {e}", path.display()))?;
                let mut data = Vec::new();
                file.take(len as u64)
                    .read_to_end(&mut data)
                    .map_err(|e| format!("buffer {i}: {}: {e}", path.display()))?;
                data
            }
        }
    };
    if data.len() < len {
        return Err(format!(
            "buffer {i}: byteLength {len} but its data has only {} bytes",
            data.len()
        ));
    }
    data.truncate(len);
    data.resize(len.next_multiple_of(4), 0);
    Ok(data)
}

/// The file a buffer URI names: a relative reference (percent-decoded) against `base`, an absolute
/// path, or a `file:` URI.
fn buffer_path(uri: &str, base: Option<&Path>) -> Result<PathBuf, String> {
    let decoded = urlencoding::decode(uri)
        .map_err(|_| format!("URI {uri:?} is not valid UTF-8 after percent-decoding"))?;
    let path = if let Some(rest) = decoded
        .strip_prefix("file://")
        .or(decoded.strip_prefix("file:"))
    {
        PathBuf::from(rest)
    } else if decoded.contains(':') && !Path::new(&*decoded).is_absolute() {
        return Err(format!(
            "URI {uri:?} has a scheme texel does not read (only data:, file: and paths)"
        ));
    } else {
        PathBuf::from(&*decoded)
    };
    if path.is_absolute() {
        return Ok(path);
    }
    base.map(|b| b.join(&path)).ok_or_else(|| {
        format!("URI {uri:?} names an external file, but the glTF was given as bytes")
    })
}

/// What a glTF file brings into a scene: its meshes, and the textures and materials they use
/// where the file's own materials were imported ([`import_gltf`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GltfScene {
    /// Every triangle primitive, one mesh each.
    pub meshes: Vec<Mesh>,
    /// The textures the meshes and imported materials name (`"PREFIX#textureN.srgb"` or
    /// `.linear` for glTF texture `N` read as colours or as data, `"PREFIX#white"`). Textures of
    /// one glTF image share its source: [`crate::Scene::texture_groups`] loads it once.
    pub textures: BTreeMap<String, TextureSpec>,
    /// The imported materials (`"PREFIX#materialN"` for glTF material `N`).
    pub materials: BTreeMap<String, MaterialSpec>,
}

impl From<Vec<Mesh>> for GltfScene {
    /// Meshes without imported textures or materials.
    fn from(meshes: Vec<Mesh>) -> Self {
        GltfScene {
            meshes,
            ..GltfScene::default()
        }
    }
}

/// Load every triangle primitive of `path` (module docs) as meshes using texture `texture`,
/// within the default [`SceneLimits`].
///
/// # Errors
/// As [`load_gltf_with`].
pub fn load_gltf(path: &Path, texture: &str) -> Result<Vec<Mesh>, SceneError> {
    load_gltf_with(path, texture, &SceneLimits::default())
}

/// Load every triangle primitive of `path` (module docs) as meshes using texture `texture`.
///
/// # Errors
/// [`SceneError::Io`] (unreadable file, not a regular file, over
/// [`SceneLimits::max_mesh_file_bytes`]), [`SceneError::Gltf`] (malformed glTF/GLB),
/// [`SceneError::MeshFile`] (invalid hierarchy, over the limits, missing or short buffer, no
/// positions or uvs, non-triangle primitives, no triangles).
pub fn load_gltf_with(
    path: &Path,
    texture: &str,
    limits: &SceneLimits,
) -> Result<Vec<Mesh>, SceneError> {
    let bytes = limits.read_mesh_file(path)?;
    let base = path.parent().unwrap_or(Path::new("."));
    load_gltf_slice(&bytes, Some(base), path, texture, limits)
}

/// Load `path` with its own materials (glTF 2.0 `pbrMetallicRoughness`): every primitive with a
/// material gets it as a scene material (its base colour factor, metallic-roughness texture and
/// factors, normal texture and scale, occlusion texture and strength; emission, alpha and
/// extensions are not read), each texture with its own sampler ([`TextureSpec::sampler`]).
/// The meshes are drawn with `texture` where it is given (replacing the glTF's base colour
/// texture), else with their base colour texture, else white. Primitives without a material
/// keep none (texel's Lambertian default). Imported names start with `prefix` and `#`.
///
/// # Errors
/// As [`load_gltf_with`]; also a material map that reads another uv set than `TEXCOORD_0`, and an
/// image whose buffer view lies outside its buffer.
pub fn import_gltf(
    path: &Path,
    texture: Option<&str>,
    prefix: &str,
    limits: &SceneLimits,
) -> Result<GltfScene, SceneError> {
    let bytes = limits.read_mesh_file(path)?;
    let base = path.parent().unwrap_or(Path::new("."));
    import_slice(&bytes, Some(base), path, texture, Some(prefix), limits)
}

/// As [`load_gltf_with`], from the bytes of a `.gltf` or `.glb` file. External buffer files are
/// read relative to `base`; with `base = None` only embedded buffers are allowed. `path` names the
/// file in errors.
///
/// # Errors
/// As [`load_gltf_with`].
pub fn load_gltf_slice(
    bytes: &[u8],
    base: Option<&Path>,
    path: &Path,
    texture: &str,
    limits: &SceneLimits,
) -> Result<Vec<Mesh>, SceneError> {
    import_slice(bytes, base, path, Some(texture), None, limits).map(|s| s.meshes)
}

/// Load the meshes of a glTF file's bytes; with `prefix`, import its materials and textures
/// ([`import_gltf`]).
fn import_slice(
    bytes: &[u8],
    base: Option<&Path>,
    path: &Path,
    texture: Option<&str>,
    prefix: Option<&str>,
    limits: &SceneLimits,
) -> Result<GltfScene, SceneError> {
    let bad = |reason: String| SceneError::MeshFile {
        path: path.to_path_buf(),
        reason: format!("cannot load glTF: {reason}"),
    };
    let gerr = |source| SceneError::Gltf {
        path: path.to_path_buf(),
        source,
    };
    check_glb_header(bytes).map_err(bad)?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(gerr)?;
    let json = document.into_json();
    check_accessor_references(&json).map_err(bad)?;
    check_accessors(&json).map_err(bad)?;
    let document = gltf::Document::from_json(json).map_err(gerr)?;
    check_hierarchy(&document).map_err(bad)?;
    let roots: Vec<gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => Vec::new(),
    };
    check_size(&document, &roots, limits).map_err(bad)?;
    let buffers = document
        .buffers()
        .map(|b| read_buffer(&b, base, blob.as_deref()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(bad)?;
    let prefix = prefix.map(|p| format!("{p}#"));
    let mut ctx = Ctx {
        path,
        texture,
        prefix: prefix.as_deref().unwrap_or(""),
        base,
        buffers: &buffers,
        limits,
        out: Vec::new(),
        textures: BTreeMap::new(),
        materials: BTreeMap::new(),
        images: BTreeMap::new(),
    };
    if document.scenes().len() == 0 {
        for mesh in document.meshes() {
            ctx.mesh(&mesh, Mat4::IDENTITY)?;
        }
    } else {
        for node in roots {
            ctx.node(node, Mat4::IDENTITY, 0)?;
        }
    }
    if ctx.out.is_empty() {
        return Err(bad("no triangles in the file's scene".into()));
    }
    Ok(GltfScene {
        meshes: ctx.out,
        textures: ctx.textures,
        materials: ctx.materials,
    })
}

/// Checks that a GLB header (`bytes` starting with `glTF`) declares a length of at least its own
/// 12 bytes: the gltf crate subtracts the header from the declared length unchecked.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if let Some(rest) = bytes.strip_prefix(b"glTF") {
        let declared = rest
            .get(4..8)
            .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]));
        match declared {
            Some(l) if l >= 12 => {}
            Some(l) => {
                return Err(format!(
                    "the GLB header declares a length of {l} bytes, less than the header's 12"
                ))
            }
            None => return Err("the GLB header is cut short".into()),
        }
    }
    Ok(())
}

/// Checks that every primitive's attributes and indices name accessors the file has:
/// gltf-json's validation indexes `accessors` with each primitive's POSITION without a bounds
/// check (and panics on a dangling one).
fn check_accessor_references(json: &gltf::json::Root) -> Result<(), String> {
    for (mi, mesh) in json.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let dangling = prim
                .attributes
                .values()
                .chain(prim.indices.as_ref())
                .find(|a| a.value() >= json.accessors.len());
            if let Some(a) = dangling {
                return Err(format!(
                    "mesh {mi} primitive {pi} refers to accessor {}, but the file has {}",
                    a.value(),
                    json.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// Checks what the scene from `roots` (every mesh where the file has no scenes) instantiates
/// against `limits`, from the document alone (no buffer is read): the meshes it makes, each
/// primitive's accessors, its triangles and vertices, and the bytes the buffers declare.
fn check_size(
    document: &gltf::Document,
    roots: &[gltf::Node],
    limits: &SceneLimits,
) -> Result<(), String> {
    let (tris, verts) = instance_counts(document, roots, limits)?;
    for mesh in document.meshes() {
        for (pi, prim) in mesh.primitives().enumerate() {
            check_primitive(&prim, limits)
                .map_err(|e| format!("mesh {} primitive {pi}: {e}", mesh.index()))?;
        }
    }
    if tris > limits.max_triangles || verts > limits.max_vertices {
        return Err(format!(
            "the scene instantiates {tris} triangles and {verts} vertices, over the limits of {} triangles and {} vertices",
            limits.max_triangles, limits.max_vertices
        ));
    }
    let total = document
        .buffers()
        .fold(0u64, |t, b| t.saturating_add(b.length() as u64));
    if total > limits.max_mesh_file_bytes {
        return Err(format!(
            "its buffers declare {total} bytes, over the limit of {} bytes",
            limits.max_mesh_file_bytes
        ));
    }
    Ok(())
}

/// The triangles and vertices the scene from `roots` instantiates (every mesh once where the file
/// has no scenes), counted from accessors; an error once the primitive instances, each a mesh of
/// its own, pass `limits.max_meshes`.
fn instance_counts(
    document: &gltf::Document,
    roots: &[gltf::Node],
    limits: &SceneLimits,
) -> Result<(u64, u64), String> {
    let (mut tris, mut verts, mut instances) = (0u64, 0u64, 0u64);
    if roots.is_empty() && document.scenes().len() == 0 {
        for mesh in document.meshes() {
            let (t, v) = mesh_counts(&mesh);
            tris = tris.saturating_add(t);
            verts = verts.saturating_add(v);
        }
        instances = document.meshes().map(|m| m.primitives().len() as u64).sum();
        if instances > limits.max_meshes {
            return Err(format!(
                "{instances} primitives (each becomes a mesh of its own), over the limit of {} \
                 meshes",
                limits.max_meshes
            ));
        }
    } else {
        let mut stack = roots.to_vec();
        while let Some(node) = stack.pop() {
            if let Some(mesh) = node.mesh() {
                let (t, v) = mesh_counts(&mesh);
                tris = tris.saturating_add(t);
                verts = verts.saturating_add(v);
                instances = instances.saturating_add(mesh.primitives().len() as u64);
                if instances > limits.max_meshes {
                    return Err(format!(
                        "the scene instantiates more primitives than the limit of {} meshes \
                         (each instance of a primitive becomes a mesh of its own)",
                        limits.max_meshes
                    ));
                }
            }
            stack.extend(node.children());
        }
    }
    Ok((tris, verts))
}
