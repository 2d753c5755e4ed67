//! Tangents for normal maps, by MikkTSpace (Mikkelsen 2008; the `bevy_mikktspace` crate), as glTF
//! asks of meshes that have a normal map and no `TANGENT` attribute.
//!
//! Convention. glTF's normal maps have `+Y` up in the image, that is towards *decreasing* `v`
//! (`v = 0` is the top row), and the bitangent is `w * cross(normal, tangent)`. MikkTSpace builds
//! its bitangent along increasing texture `t`, so it is given `t = 1 - v`: its sign `w` then makes
//! `w * cross(n, t)` point up the image, as glTF's renderers expect (tested in
//! `tests/tangents.rs` against a plane whose up direction is known).

use bevy_mikktspace::{generate_tangents, Geometry, TangentSpace};
use glam::{Vec3, Vec4};

use crate::model::Mesh;

struct Faces<'a> {
    mesh: &'a Mesh,
    tangents: Vec<Vec4>,
}

impl Faces<'_> {
    fn index(&self, face: usize, vert: usize) -> usize {
        self.mesh.triangles[face][vert] as usize
    }

    fn face_normal(&self, face: usize) -> Vec3 {
        let [a, b, c] = self.mesh.triangles[face].map(|i| self.mesh.positions[i as usize]);
        (b - a).cross(c - a).normalize_or(Vec3::Y)
    }
}

impl Geometry for Faces<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.index(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        match &self.mesh.normals {
            Some(n) => n[self.index(face, vert)].normalize_or(self.face_normal(face)),
            None => self.face_normal(face),
        }
        .to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.mesh.uvs[self.index(face, vert)];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(&mut self, tangent_space: Option<TangentSpace>, face: usize, vert: usize) {
        let i = self.index(face, vert);
        let t = tangent_space.unwrap_or_default().tangent_encoded();
        self.tangents[i] = Vec4::from_array(t);
    }
}

impl Mesh {
    /// Generate [`Mesh::tangents`] with MikkTSpace from the positions, normals (each face's own
    /// normal where the mesh has none) and uvs. A vertex shared by faces whose tangent spaces
    /// differ keeps the last one written (split vertices at uv seams to avoid that, as exporters
    /// do); a vertex MikkTSpace cannot give a tangent (degenerate, isolated) gets `(1, 0, 0, 1)`.
    pub fn generate_tangents(&mut self) {
        let mut faces = Faces {
            mesh: self,
            tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); self.positions.len()],
        };
        // The crate's error type is uninhabited: generation cannot fail.
        let _ = generate_tangents(&mut faces);
        let tangents = faces.tangents;
        self.tangents = Some(tangents);
    }
}
