//! One frame of a prepared scene for one filter: [`PreparedScene::plan`] makes the samplers,
//! builds and charges what they need, and hands out the settings and draw calls every renderer
//! (CPU, reference, GPU) takes; [`FrameOptions`] says how the frame is drawn and
//! [`FramePlan::render`] draws it.

use texel_quality::Encoding;
use texel_raster::{
    render, ColorTarget, Derivatives, DrawCall, Frame, Perspective, RenderSettings, View,
};
use texel_scene::Camera;
use texel_texture::Sampler;

use crate::{ColorHandling, Error, Filter, MemoryBudget, PreparedScene};

/// How one frame is drawn beyond what the scene says: what each pixel shows, how derivatives
/// and attributes are computed, the colour target and the threads. The same rules for
/// `texel render`, [`FramePlan::render`], the facade's `render_scene` and the viewer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameOptions {
    /// What each pixel shows: the textured colour, or a debug view.
    pub view: View,
    /// How the sampler's screen derivatives are computed.
    pub derivatives: Derivatives,
    /// How attributes are interpolated across a triangle.
    pub perspective: Perspective,
    /// Draw into linear floats, unclamped (an OpenEXR output, or passes to accumulate), rather
    /// than the 8-bit target of the image.
    pub float: bool,
    /// Worker threads; `None`: all cores.
    pub threads: Option<usize>,
}

impl FrameOptions {
    /// Set `settings` (a scene's, whose target the colour handling `color` chose) to draw as
    /// these options say, and say how the frame's 8-bit image is encoded: the textured colour as
    /// `color` says; a debug view, whose values are meant for display, into an sRGB target and
    /// encoded sRGB whatever `color` is. With [`FrameOptions::float`] the target is
    /// [`ColorTarget::Float`] whatever the view.
    pub fn apply(&self, settings: &mut RenderSettings<'_>, color: ColorHandling) -> Encoding {
        settings.view = self.view;
        settings.derivatives = self.derivatives;
        settings.perspective = self.perspective;
        settings.threads = self.threads;
        let encoding = if self.view == View::Color {
            color.encoding()
        } else {
            settings.target = ColorTarget::Srgb8;
            Encoding::Srgb
        };
        if self.float {
            settings.target = ColorTarget::Float;
        }
        encoding
    }
}

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

    /// The frame's settings seen by the scene's camera, drawn as `options` say
    /// ([`FrameOptions::apply`]), and the encoding of its 8-bit image.
    pub fn settings_with(&self, options: &FrameOptions) -> (RenderSettings<'_>, Encoding) {
        let mut settings = self.settings();
        let encoding = options.apply(&mut settings, self.scene.color);
        (settings, encoding)
    }

    /// The frame seen by the scene's camera, drawn on the CPU as `options` say, and the encoding
    /// of its 8-bit image.
    ///
    /// # Errors
    /// [`Error::Raster`] (an invalid size or scissor).
    pub fn render(&self, options: &FrameOptions) -> Result<(Frame, Encoding), Error> {
        let (settings, encoding) = self.settings_with(options);
        Ok((render(&settings, &self.draws())?, encoding))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene's settings as `color` sets its target.
    fn scene_settings(color: ColorHandling) -> RenderSettings<'static> {
        let mut s = RenderSettings::new(4, 4);
        s.target = color.target();
        s
    }

    #[test]
    fn frame_options_set_the_view_target_and_encoding() {
        for color in ColorHandling::ALL {
            // The textured colour keeps the scene's target and encodes as the handling says.
            let mut s = scene_settings(color);
            let want = s.target;
            let options = FrameOptions {
                derivatives: Derivatives::Quad,
                perspective: Perspective::Affine,
                threads: Some(3),
                ..FrameOptions::default()
            };
            assert_eq!(options.apply(&mut s, color), color.encoding());
            assert_eq!(s.target, want);
            assert_eq!(
                (s.derivatives, s.perspective, s.threads),
                (Derivatives::Quad, Perspective::Affine, Some(3))
            );
            // A debug view is drawn into sRGB and encoded sRGB whatever the handling.
            let mut s = scene_settings(color);
            let lod = FrameOptions {
                view: View::Lod,
                ..FrameOptions::default()
            };
            assert_eq!(lod.apply(&mut s, color), Encoding::Srgb);
            assert_eq!((s.view, s.target), (View::Lod, ColorTarget::Srgb8));
            // A float target wins over both, the encoding staying the view's.
            let mut s = scene_settings(color);
            let float = FrameOptions {
                view: View::Lod,
                float: true,
                ..FrameOptions::default()
            };
            assert_eq!(float.apply(&mut s, color), Encoding::Srgb);
            assert_eq!(s.target, ColorTarget::Float);
        }
    }
}
