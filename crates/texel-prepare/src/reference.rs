//! The converging reference of a prepared scene: [`PreparedScene::reference`], run as a
//! [`ReferenceRun`] says (threads, scissor, progress, stop flag).

use std::sync::atomic::AtomicBool;

use texel_raster::{render_reference_adaptive, ReferenceEstimate, ReferencePlan, ReferenceStatus};
use texel_scene::Camera;

use crate::{Error, PreparedScene};

/// How [`PreparedScene::reference`] runs a converging reference.
#[derive(Clone, Copy, Default)]
pub struct ReferenceRun<'a> {
    /// Samples, tolerance and seed ([`ReferencePlan`]).
    pub plan: ReferencePlan,
    /// Worker threads; `None`: all cores.
    pub threads: Option<usize>,
    /// Only the pixels `x0 <= i < x1, y0 <= j < y1` of `[x0, y0, x1, y1]`, each exactly what the
    /// whole frame gives it; the others hold the background with zero error. `None`: every pixel.
    pub scissor: Option<[u32; 4]>,
    /// Called from worker threads as passes finish.
    pub progress: Option<&'a (dyn Fn(&ReferenceStatus) + Sync)>,
    /// Once set, the reference ends after the current pass, marked interrupted.
    pub stop: Option<&'a AtomicBool>,
}

impl PreparedScene {
    /// The converging reference of this scene seen by `camera` ([`texel_raster::adaptive`]): its
    /// textures at level 0 with each mesh's address modes, the reference geometry, and every
    /// pixel's mean and standard error.
    ///
    /// # Errors
    /// [`Error::Raster`]: an invalid plan or scissor, or [`texel_raster::RasterError::Interrupted`] for a stop
    /// before the first pass finished.
    pub fn reference(
        &self,
        camera: &Camera,
        run: &ReferenceRun<'_>,
    ) -> Result<ReferenceEstimate, Error> {
        let plan = self.reference_plan()?;
        let draws = plan.reference_draws_from(camera)?;
        let mut settings = plan.settings_from(camera);
        settings.threads = run.threads;
        settings.scissor = run.scissor;
        Ok(render_reference_adaptive(
            &settings,
            &draws,
            &run.plan,
            run.progress,
            run.stop,
        )?)
    }
}
