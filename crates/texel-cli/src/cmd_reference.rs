//! `texel reference`: the supersampled ground truth.

use anyhow::Result;
use texel_raster::render_reference_strata;

use crate::cli::ReferenceArgs;
use crate::filters::Filter;
use crate::input::{load_scene, Input};
use crate::output::{encoding, write_frame};
use crate::progress;
use texel::PreparedScene;

/// Seed of the reference's jitter: fixed, so references are reproducible.
pub const SEED: u64 = 0x7e_7e1;

/// Split `spp` samples into an `n x m` stratification with `n <= m` as square as possible
/// (256 -> 16 x 16, 512 -> 16 x 32, 7 -> 1 x 7).
pub fn strata(spp: u32) -> (u32, u32) {
    let mut n = (f64::from(spp).sqrt().floor() as u32).max(1);
    while !spp.is_multiple_of(n) {
        n -= 1;
    }
    (n, spp / n)
}

/// Render the reference of a prepared scene, with a progress bar on a terminal.
pub fn reference_frame(scene: &PreparedScene, spp: u32) -> Result<texel_raster::Frame> {
    reference_frame_from(scene, spp, &scene.scene.camera)
}

/// [`reference_frame`] seen by `camera` instead of the scene's.
pub fn reference_frame_from(
    scene: &PreparedScene,
    spp: u32,
    camera: &texel_scene::Camera,
) -> Result<texel_raster::Frame> {
    // The reference samples level 0 bilinearly with each mesh's address modes; the filter only
    // supplies those.
    let samplers = scene.samplers(Filter::Bilinear)?;
    let draws = scene.reference_draws_from(&samplers, camera)?;
    let settings = scene.settings_for(&samplers, camera);
    let (n, m) = strata(spp);
    let pb = progress::bar(1000, "reference");
    let report = |done: u64, total: u64| pb.set_position(done * 1000 / total.max(1));
    let max = texel_raster::reference::MAX_SPP_SIDE;
    anyhow::ensure!(
        m <= max,
        "--spp {spp} stratifies as {n} x {m}, over {max} per side: choose a number with a divisor near its square root (e.g. 256, 512, 1024)"
    );
    let frame = render_reference_strata(&settings, &draws, [n, m], SEED, Some(&report))?;
    pb.finish_and_clear();
    Ok(frame)
}

/// Run `texel reference`.
pub fn run(args: &ReferenceArgs, input: &mut Input) -> Result<()> {
    let scene = load_scene(&args.scene, input)?;
    let frame = reference_frame(&scene, args.spp)?;
    write_frame(&args.output, &frame, encoding(args.scene.color))
}

#[cfg(test)]
mod tests {
    use super::strata;

    #[test]
    fn stratifications() {
        assert_eq!(strata(256), (16, 16));
        assert_eq!(strata(512), (16, 32));
        assert_eq!(strata(1024), (32, 32));
        assert_eq!(strata(1), (1, 1));
        assert_eq!(strata(7), (1, 7));
        assert_eq!(strata(12), (3, 4));
    }
}
