//! Mappings into texture space, the stage before sampling: directions to the sphere's texture
//! coordinates (equirectangular, cube, octahedral) and the lecture's surface projections.
//! Independent of every sampling floor.

pub mod sphere;
