//! Every GPU mode against texel's CPU path on the built-in scenes, at reduced size: the shader
//! filters the same texels with the same formulas, so the images must agree to at least 45 dB
//! PSNR over covered pixels (8-bit sRGB output). They differ by float rounding (`f32` in another
//! order, libm's `log2` against texel's `fast_log2`) and by the device's sub-pixel precision
//! (its interpolated uv, and from it the quad derivatives and the lod).
//!
//! Needs a Vulkan adapter (Mesa's lavapipe: `apt-get install mesa-vulkan-drivers`). Without
//! one the tests print why and pass, unless `CI=true`, where a missing adapter fails them.

use texel::raster::{ColorTarget, Derivatives};
use texel::texture::Convention;
use texel::{Filter, MemoryBudget, PreparedScene, Scene, SceneOptions};
use texel_gpu::{Gpu, GpuError, GpuFilter};

/// The device, or `None` (with the reason printed) where there is no Vulkan adapter and CI does not
/// demand one. A GL adapter alone does not count: GLSL ES has no fine derivatives (naga writes
/// `dFdx` for `dpdxFine`, coarse on llvmpipe), so mip-nearest and trilinear there differ from the
/// CPU's fine quad derivatives in whole quads by up to 255 codes (24-30 dB), where lavapipe
/// agrees to within 1 code.
fn gpu() -> Option<Gpu> {
    let ci = std::env::var("CI").as_deref() == Ok("true");
    match Gpu::new(None) {
        Ok(g) if g.info().backend == "Vulkan" => {
            eprintln!("adapter: {}", g.info());
            Some(g)
        }
        Ok(g) if !ci => {
            eprintln!("skipped: no Vulkan adapter, only {}", g.info());
            None
        }
        Err(e @ GpuError::NoAdapter) if !ci => {
            eprintln!("skipped: {e}");
            None
        }
        Ok(g) => panic!("CI=true but no Vulkan adapter, only {}", g.info()),
        Err(e) => panic!("{e}"),
    }
}

/// PSNR (dB) of the 8-bit sRGB encodings of `a` and `b` over pixels both cover, and the largest
/// difference of one 8-bit channel.
fn psnr(a: &texel::Frame, b: &texel::Frame) -> (f64, u8, usize) {
    let enc = |x: f32| texel::texture::linear_to_srgb8(x);
    let (mut sum, mut n, mut worst) = (0.0f64, 0usize, 0u8);
    for k in 0..a.color.len() {
        if !(a.covered(k) && b.covered(k)) {
            continue;
        }
        for c in 0..3 {
            let d = enc(a.color[k][c]).abs_diff(enc(b.color[k][c]));
            worst = worst.max(d);
            sum += f64::from(d) * f64::from(d);
        }
        n += 3;
    }
    let mse = sum / n.max(1) as f64;
    let db = if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    };
    (db, worst, n / 3)
}

/// `scene` prepared at the tests' reduced size, 160 x 96.
fn small(scene: &str) -> PreparedScene {
    small_with(scene, Convention::Gl)
}

/// `scene` at 160 x 96 with the lab modes under `convention`.
fn small_with(scene: &str, convention: Convention) -> PreparedScene {
    let options = SceneOptions {
        size: Some((160, 96)),
        convention,
        ..SceneOptions::default()
    };
    let scene = Scene::load(scene).unwrap();
    PreparedScene::new(scene, &options, &mut MemoryBudget::half_of_machine()).unwrap()
}

/// Every filter the GPU path has against the CPU path on `scene`.
fn agree(scene: &str) {
    agree_in(scene, Convention::Gl, GpuFilter::filters().collect());
}

/// `filters` on the GPU against the CPU path on `scene`, the lab modes under `convention`.
fn agree_in(scene: &str, convention: Convention, filters: Vec<Filter>) {
    let Some(gpu) = gpu() else { return };
    let prepared = small_with(scene, convention);
    let mut settings = prepared.settings();
    settings.derivatives = Derivatives::Quad;
    settings.target = ColorTarget::Float;
    for filter in filters {
        let name = filter.name();
        let samplers = prepared.samplers(filter).unwrap();
        let draws = prepared.draws(&samplers);
        let cpu = texel::render(&settings, &draws).unwrap();
        let gpu_frame =
            texel_gpu::render(&gpu, &settings, &draws, GpuFilter::of(filter).unwrap()).unwrap();
        let (db, worst, covered) = psnr(&cpu, &gpu_frame);
        eprintln!("{name}: {db:.1} dB over {covered} pixels, largest difference {worst}/255");
        assert!(covered > 1000, "{name}: {covered} covered pixels");
        assert!(
            db >= 45.0,
            "{name}: {db:.1} dB (largest difference {worst}/255)"
        );
        // The GPU's depth target holds the CPU's NDC depth (coverage is implied by it): equal
        // coverage up to edge pixels, equal depths up to f32 interpolation.
        let both: Vec<usize> = (0..cpu.depth.len())
            .filter(|&k| cpu.covered(k) && gpu_frame.covered(k))
            .collect();
        assert!(
            both.len() * 100 >= 99 * cpu.covered_pixels(),
            "{name}: {}",
            both.len()
        );
        let worst_z = both
            .iter()
            .map(|&k| (cpu.depth[k] - gpu_frame.depth[k]).abs())
            .fold(0.0f32, f32::max);
        assert!(worst_z < 1e-4, "{name}: depths differ by {worst_z}");
    }
}

#[test]
fn ground_agrees_with_the_cpu() {
    agree("builtin:ground");
}

#[test]
fn zoneplate_agrees_with_the_cpu() {
    agree("builtin:zoneplate");
}

#[test]
fn cube_agrees_with_the_cpu() {
    agree("builtin:cube");
}

/// The lab's eight modes under the handout's formulas, on the scenes the lab grades on and on
/// the ground (uv to +-250, every level). Not on the zone plate: its pixel centres map to texel
/// centres one to one, which is where the handout's rounding `round(x)` switches texels, so
/// nearest there follows the last bit of each path's interpolation.
#[test]
fn the_lab_convention_agrees_with_the_cpu() {
    let modes: Vec<Filter> = (1..=8).map(|m| Filter::from_lab_mode(m).unwrap()).collect();
    for scene in [
        "builtin:ground",
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/lab/plane.toml"),
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/lab/tunnel.toml"),
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/lab/wall.toml"),
    ] {
        eprintln!("{scene}, --convention lab:");
        agree_in(scene, Convention::Lab, modes.clone());
    }
}

/// The two conventions differ on the GPU as on the CPU (the lab's texel centres move every
/// bilinear tap), and draws of both conventions in one pass, or the lab convention with a filter
/// outside the eight modes, are refused.
#[test]
fn the_conventions_differ_and_mixed_draws_are_refused() {
    let Some(gpu) = gpu() else { return };
    let gl = small_with("builtin:zoneplate", Convention::Gl);
    let lab = small_with("builtin:zoneplate", Convention::Lab);
    let mut settings = gl.settings();
    settings.target = ColorTarget::Float;
    let f = GpuFilter::Shader(Filter::Bilinear);
    let gl_samplers = gl.samplers(Filter::Bilinear).unwrap();
    let lab_samplers = lab.samplers(Filter::Bilinear).unwrap();
    let a = texel_gpu::render(&gpu, &settings, &gl.draws(&gl_samplers), f).unwrap();
    let b = texel_gpu::render(&gpu, &settings, &lab.draws(&lab_samplers), f).unwrap();
    let (db, worst, _) = psnr(&a, &b);
    eprintln!("gl against lab, bilinear: {db:.1} dB, largest difference {worst}/255");
    assert!(db < 40.0 && worst > 8, "{db:.1} dB, {worst}/255");
    let mut mixed = gl.draws(&gl_samplers);
    mixed.extend(lab.draws(&lab_samplers));
    let e = gpu.prepare(&mixed, f).err().expect("refused");
    assert!(e.to_string().contains("both conventions"), "{e}");
    let e = gpu
        .prepare(&lab.draws(&lab_samplers), GpuFilter::Shader(Filter::Ewa))
        .err()
        .expect("refused");
    assert!(e.to_string().contains("lab's eight modes"), "{e}");
}

/// With timestamp queries (lavapipe has them) the render pass's device time is positive and no
/// longer than the whole call's wall time; without them it is `None`.
#[test]
fn device_time_is_measured_when_the_device_can() {
    let Some(gpu) = gpu() else { return };
    let prepared = small("builtin:ground");
    let samplers = prepared.samplers(Filter::Trilinear).unwrap();
    let draws = prepared.draws(&samplers);
    let gpu_draws = gpu
        .prepare(&draws, GpuFilter::Shader(Filter::Trilinear))
        .unwrap();
    let t0 = std::time::Instant::now();
    let (frame, ms) = gpu_draws.render_timed(&prepared.settings()).unwrap();
    let wall = t0.elapsed().as_secs_f64() * 1e3;
    assert!(frame.covered_pixels() > 0);
    match ms {
        Some(ms) => {
            assert!(gpu.has_timestamps());
            assert!(ms > 0.0 && ms <= wall, "device {ms} ms, wall {wall} ms");
        }
        None => assert!(!gpu.has_timestamps()),
    }
}

/// Passes timed back to back: one positive time per pass, in two submissions (more passes than
/// `PASSES_PER_SUBMIT`), together no longer than the call; the frame drawn after them equals
/// the one drawn before them bit for bit.
#[test]
fn passes_timed_back_to_back() {
    let Some(gpu) = gpu() else { return };
    let prepared = small("builtin:ground");
    let samplers = prepared.samplers(Filter::Trilinear).unwrap();
    let draws = prepared.draws(&samplers);
    let gpu_draws = gpu
        .prepare(&draws, GpuFilter::Shader(Filter::Trilinear))
        .unwrap();
    let mut settings = prepared.settings();
    settings.target = ColorTarget::Float;
    let before = gpu_draws.render(&settings).unwrap();
    let passes = texel_gpu::PASSES_PER_SUBMIT + 3;
    let t0 = std::time::Instant::now();
    let times = gpu_draws.pass_times(&settings, passes).unwrap();
    let wall = t0.elapsed().as_secs_f64() * 1e3;
    match times {
        Some(times) => {
            assert!(gpu.has_timestamps());
            assert_eq!(times.len(), passes as usize);
            assert!(times.iter().all(|&ms| ms > 0.0), "{times:?}");
            let sum: f64 = times.iter().sum();
            assert!(sum <= wall, "device {sum} ms in all, wall {wall} ms");
        }
        None => assert!(!gpu.has_timestamps()),
    }
    let after = gpu_draws.render(&settings).unwrap();
    assert_eq!(before.covered_pixels(), after.covered_pixels());
    assert!(before.color == after.color && before.depth == after.depth);
    // Nothing to time is no time.
    assert_eq!(
        gpu_draws.pass_times(&settings, 0).unwrap().map(|t| t.len()),
        gpu.has_timestamps().then_some(0)
    );
}

/// `set_clip_from_world` moves the camera of prepared draws: the frame equals the one prepared
/// with the new camera, bit for bit. A scissor keeps the pixels inside (bit for bit the whole
/// frame's) and leaves the background outside.
#[test]
fn a_moved_camera_and_a_scissor_match_fresh_draws() {
    let Some(gpu) = gpu() else { return };
    let prepared = small("builtin:ground");
    let samplers = prepared.samplers(Filter::Aniso8).unwrap();
    let mut draws = prepared.draws(&samplers);
    let mut settings = prepared.settings();
    settings.target = ColorTarget::Float;
    let first = gpu
        .prepare(&draws, GpuFilter::Shader(Filter::Aniso16))
        .unwrap();
    let mut camera = prepared.scene.camera;
    camera.eye.y += 0.7;
    camera.target.x += 1.5;
    let moved = camera.clip_from_world(160.0 / 96.0);
    first.set_clip_from_world(moved);
    let via_update = first.render(&settings).unwrap();
    for d in &mut draws {
        d.clip_from_world = moved;
    }
    let fresh =
        texel_gpu::render(&gpu, &settings, &draws, GpuFilter::Shader(Filter::Aniso16)).unwrap();
    assert_eq!(via_update.color, fresh.color);
    assert!(fresh.covered_pixels() > 1000);

    let scissor = [30, 20, 111, 77];
    let part = first
        .render(&texel::raster::RenderSettings {
            scissor: Some(scissor),
            ..settings
        })
        .unwrap();
    for j in 0..96 {
        for i in 0..160 {
            let k = fresh.index(i, j);
            if (30..111).contains(&i) && (20..77).contains(&j) {
                assert_eq!(part.color[k], fresh.color[k], "pixel ({i}, {j})");
            } else {
                assert_eq!(part.color[k], settings.background, "pixel ({i}, {j})");
                assert!(!part.covered(k));
            }
        }
    }
}

/// A texel filter the shader lacks, built by hand, is refused with an error, not a panic.
#[test]
fn filters_the_shader_lacks_are_refused() {
    let Some(gpu) = gpu() else { return };
    let prepared = small("builtin:ground");
    let samplers = prepared.samplers(Filter::Trilinear).unwrap();
    let draws = prepared.draws(&samplers);
    for f in [Filter::Ripmap, Filter::Sat] {
        assert_eq!(GpuFilter::of(f), None);
        let e = gpu
            .prepare(&draws, GpuFilter::Shader(f))
            .err()
            .expect("refused");
        assert!(e.to_string().contains("summed-area table"), "{e}");
    }
}
