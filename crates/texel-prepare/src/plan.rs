//! One frame of a prepared scene for one filter: [`PreparedScene::plan`] makes the samplers,
//! builds and charges what they need, and hands out the settings and draw calls every renderer
//! (CPU, reference, GPU) takes.

use texel_raster::{DrawCall, RenderSettings};
use texel_scene::Camera;
use texel_texture::Sampler;

use crate::{Error, Filter, MemoryBudget, PreparedScene};

/// The samplers of one filter on a prepared scene (one per mesh, then the textures' own, then the
/// environment's), with their ripmaps and summed-area tables built: what a frame needs besides
/// the scene. Borrowing the plan gives the frame's settings and draw calls.
pub struct FramePlan<'a> {
    scene: &'a PreparedScene,
    samplers: Vec<Sampler>,
    structure_bytes: u64,
}

impl PreparedScene {
    /// The frame plan of `filter` (`None`: a glTF mesh's own sampler filters, else trilinear):
    /// [`PreparedScene::samplers`] (or [`PreparedScene::default_samplers`]), with the ripmaps
    /// and summed-area tables they read built and charged to `budget` once per texture
    /// ([`PreparedScene::build_structures_within`]).
    ///
    /// # Errors
    /// [`Error::OverBudget`], also for a structure over a texture's own limit.
    pub fn plan(
        &self,
        filter: Option<Filter>,
        budget: &mut MemoryBudget,
    ) -> Result<FramePlan<'_>, Error> {
        let samplers = match filter {
            Some(f) => self.samplers(f)?,
            None => self.default_samplers()?,
        };
        let structure_bytes = self.build_structures_within(&samplers, budget)?;
        Ok(FramePlan {
            scene: self,
            samplers,
            structure_bytes,
        })
    }

    /// The reference's plan: every texture read at level 0, bilinearly, with each mesh's address
    /// modes (the samplers of [`Filter::Bilinear`]; they need no structures). Its
    /// [`FramePlan::reference_draws_from`] draws the reference geometry.
    ///
    /// # Errors
    /// As [`PreparedScene::samplers`].
    pub fn reference_plan(&self) -> Result<FramePlan<'_>, Error> {
        Ok(FramePlan {
            scene: self,
            samplers: self.samplers(Filter::Bilinear)?,
            structure_bytes: 0,
        })
    }
}

impl FramePlan<'_> {
    /// The samplers, in the order [`PreparedScene::samplers`] gives them.
    pub fn samplers(&self) -> &[Sampler] {
        &self.samplers
    }

    /// Bytes of every structure the frame reads, pyramids included, each texture counted once
    /// ([`PreparedScene::build_structures`]); 0 for the reference's plan.
    pub fn structure_bytes(&self) -> u64 {
        self.structure_bytes
    }

    /// The frame's settings seen by the scene's camera ([`PreparedScene::settings_for`]).
    pub fn settings(&self) -> RenderSettings<'_> {
        self.settings_from(&self.scene.scene.camera)
    }

    /// The frame's settings seen by `camera` (the environment's background follows it).
    pub fn settings_from(&self, camera: &Camera) -> RenderSettings<'_> {
        self.scene.settings_for(&self.samplers, camera)
    }

    /// The draw calls seen by the scene's camera ([`PreparedScene::draws`]).
    pub fn draws(&self) -> Vec<DrawCall<'_>> {
        self.scene.draws(&self.samplers)
    }

    /// The draw calls seen by `camera` ([`PreparedScene::draws_from`]).
    pub fn draws_from(&self, camera: &Camera) -> Vec<DrawCall<'_>> {
        self.scene.draws_from(&self.samplers, camera)
    }

    /// The reference geometry's draw calls seen by `camera`
    /// ([`PreparedScene::reference_draws_from`]).
    ///
    /// # Errors
    /// As [`PreparedScene::reference_draws_from`].
    pub fn reference_draws_from(&self, camera: &Camera) -> Result<Vec<DrawCall<'_>>, Error> {
        self.scene.reference_draws_from(&self.samplers, camera)
    }
}
