//! `texel bench`: median frame time per filter, measured by [`texel::timing::time_filters`]
//! (what is timed: [`texel::timing`]), with the clear's cost reported apart (`clear ms`), as
//! `llvmpipe_bench.py` clears its framebuffer and calls `glFinish` before starting the clock.
//! The median of `--frames` timed frames after `--warmup` untimed ones (lasting at least
//! 200 ms unless `--warmup 0`), on a pool of `--threads` workers built once.
//!
//! The clear leaves the frame marked as holding it (`Frame::holds_clear`), as a GPU's fast
//! clear does, so a frame larger than the last-level cache is drawn tile by tile in scratch and
//! streamed out without reading the frame (`--streaming`, [`texel::raster::Streaming`]); the report
//! says whether the timed frames were (`streamed`).

use std::io::Write;
use std::time::Instant;

use anyhow::{Context, Result};
use texel::timing::{time_filters, warm_up, BenchPlan, FilterTiming};
use texel::{Filter, MemoryBudget, PreparedScene};

use crate::cli::{BenchArgs, TargetArg};
use crate::filters::{parse_gpu_list, parse_list, GpuJob};
use crate::input::{check_storage, load_scene, Input};
use crate::threads::{thread_count, workers};

/// `--gpu`: per job, upload once, then time whole frames (render and read back) on the device,
/// and where the adapter has timestamp queries the device time of as many render passes recorded
/// back to back ([`texel_gpu::GpuDraws::pass_times`]).
fn time_gpu(
    args: &BenchArgs,
    gpu: &texel_gpu::Gpu,
    scene: &PreparedScene,
    jobs: &[GpuJob],
    budget: &mut MemoryBudget,
) -> Result<Vec<FilterTiming>> {
    let mut out = Vec::new();
    for &(label, filter, gpu_filter) in jobs {
        let plan = scene.plan(Some(filter), budget)?;
        let draws = plan.draws();
        let mut settings = plan.settings();
        settings.derivatives = texel::raster::Derivatives::Quad;
        if args.target == TargetArg::Float {
            settings.target = texel::ColorTarget::Float;
        }
        // Held while this job runs, freed with its uploads before the next.
        let held = texel_gpu::prepare_bytes(&draws)
            + texel_gpu::frame_bytes(settings.width, settings.height);
        budget.take(
            "the GPU's copies of the textures and meshes, and its frame",
            held,
        )?;
        let prepared = gpu.prepare(&draws, gpu_filter)?;
        warm_up(args.warmup, 1, || {
            std::hint::black_box(prepared.render(&settings)?);
            Ok::<_, texel_gpu::GpuError>(())
        })?;
        let mut times = Vec::new();
        for _ in 0..args.frames {
            let t0 = Instant::now();
            std::hint::black_box(prepared.render(&settings)?);
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        // Device time of as many passes, back to back: between read-back frames the device
        // idles and may clock down (docs/guide/gpu.md), so warm-up passes run
        // back to back first, as the frames' warm-up does (`--warmup` of them and at least
        // 200 ms unless 0).
        if gpu.has_timestamps() {
            let batch = args.warmup.min(texel_gpu::PASSES_PER_SUBMIT);
            warm_up(args.warmup, batch, || {
                prepared.pass_times(&settings, batch).map(drop)
            })?;
        }
        let device = prepared
            .pass_times(&settings, args.frames)?
            .unwrap_or_default();
        // For the GPU the second column is the render pass's device time (0 without timestamp
        // queries).
        out.push(FilterTiming::of(label, times, device, false));
        drop(prepared);
        budget.release(held);
    }
    Ok(out)
}

/// Run `texel bench`.
pub(crate) fn run(args: &BenchArgs, input: &mut Input) -> Result<()> {
    check_storage(&args.scene, args.gpu)?;
    let scene = load_scene(&args.scene, input)?;
    // The GPU's rows are checked before the (slower) adapter start; the CPU's list as before.
    let (filters, jobs) = if args.gpu {
        (Vec::new(), parse_gpu_list(&args.filters)?)
    } else {
        (parse_list(&args.filters)?, Vec::new())
    };
    let budget = &mut input.budget;
    texel::raster::limit_level(args.simd.limit());
    texel::raster::set_streaming(args.streaming);
    let gpu = if args.gpu {
        Some(texel_gpu::Gpu::new(args.adapter.as_deref())?)
    } else {
        None
    };
    let timings = if let Some(gpu) = &gpu {
        time_gpu(args, gpu, &scene, &jobs, budget)?
    } else {
        time_cpu(args, &scene, &filters, budget)?
    };
    let measured = Measured {
        args,
        scene: &scene,
        gpu: gpu.as_ref(),
        timings: &timings,
        threads: thread_count(args.threads),
        streamed: streamed(&timings),
    };
    let mut stdout = std::io::stdout().lock();
    if args.json {
        measured.write_json(&mut stdout)
    } else {
        measured.write_text(&mut stdout)
    }
}

/// Each filter's frame times on the CPU.
fn time_cpu(
    args: &BenchArgs,
    scene: &PreparedScene,
    filters: &[Filter],
    budget: &mut MemoryBudget,
) -> Result<Vec<FilterTiming>> {
    let plan = BenchPlan {
        warmup: args.warmup,
        frames: args.frames,
        float_target: args.target == TargetArg::Float,
        threads: workers(args.threads),
    };
    Ok(time_filters(scene, filters, &plan, budget)?)
}

/// Whether the frames streamed (every filter's frames have the same size and target, so all
/// stream or none does).
fn streamed(timings: &[FilterTiming]) -> bool {
    timings.iter().any(|t| t.streamed)
}

/// A bench run's timings and what they were measured on, as they are printed.
struct Measured<'a> {
    args: &'a BenchArgs,
    scene: &'a PreparedScene,
    gpu: Option<&'a texel_gpu::Gpu>,
    timings: &'a [FilterTiming],
    threads: usize,
    streamed: bool,
}

impl Measured<'_> {
    /// The timings as one JSON object.
    fn write_json(&self, stdout: &mut impl Write) -> Result<()> {
        let (args, scene, gpu, timings) = (self.args, self.scene, self.gpu, self.timings);
        let (threads, streamed) = (self.threads, self.streamed);
        let renderer = if args.gpu { "texel-gpu" } else { "texel" };
        let second = if args.gpu { "device_ms" } else { "clear_ms" };
        // With --gpu, the adapter the frames ran on (the CPU's fields stay: they describe the
        // host).
        let adapter = gpu.map_or(String::new(), |g| {
            format!(
                "\n \"adapter\": {},",
                serde_json::Value::from(g.info().to_string())
            )
        });
        let entries = |value: fn(&FilterTiming) -> f64| {
            timings
                .iter()
                .map(|t| format!("  \"{}\": {:.3}", t.filter, value(t)))
                .collect::<Vec<String>>()
                .join(",\n")
        };
        writeln!(
        stdout,
        "{{\n \"renderer\": \"{renderer}\",{adapter}\n \"cpu\": {},\n \"simd\": \"{}\",\n \"target\": \"{}\",\n \"precision\": \"{}\",\n \"texture_storage\": \"{}\",\n \"streaming\": \"{}\",\n \"streamed\": {},\n \"threads\": {threads},\n \"width\": {},\n \"height\": {},\n \"frames\": {},\n \"median_ms\": {{\n{}\n }},\n \"{second}\": {{\n{}\n }}\n}}",
        serde_json::Value::from(cpu_model()),
        simd_level(),
        target_name(args.target),
        args.scene.precision.name(),
        scene.storage_name(),
        args.streaming.name(),
        streamed,
        scene.width,
        scene.height,
        args.frames,
        entries(|t| t.median_ms),
        entries(|t| t.second_ms)
    )
    .context("cannot write to stdout")?;
        Ok(())
    }

    /// The timings as a table with a header naming the run.
    fn write_text(&self, stdout: &mut impl Write) -> Result<()> {
        let (args, scene, gpu, timings) = (self.args, self.scene, self.gpu, self.timings);
        let (threads, streamed) = (self.threads, self.streamed);
        writeln!(
        stdout,
        "texel bench: {} at {}x{}, {threads} threads, {} target, median of {} frames after {} warm-up",
        texel_io::escape(&args.scene.scene),
        scene.width,
        scene.height,
        target_name(args.target),
        args.frames,
        args.warmup
    )?;
        writeln!(
            stdout,
            "cpu: {}; simd: {}; precision: {}; textures: {}; streaming: {} ({})",
            cpu_model(),
            simd_level(),
            args.scene.precision.name(),
            scene.storage_name(),
            args.streaming.name(),
            if streamed { "streamed" } else { "in place" }
        )?;
        if let Some(gpu) = gpu {
            writeln!(stdout, "gpu: {}", gpu.info())?;
        }
        writeln!(
            stdout,
            "{:<12} {:>10} {:>10} {:>10} {:>10}",
            "filter",
            "median ms",
            "min ms",
            "max ms",
            if args.gpu { "device ms" } else { "clear ms" }
        )?;
        for t in timings {
            writeln!(
                stdout,
                "{:<12} {:>10.3} {:>10.3} {:>10.3} {:>10.3}",
                t.filter, t.median_ms, t.min_ms, t.max_ms, t.second_ms
            )?;
        }
        Ok(())
    }
}

/// The target's name in the report.
fn target_name(t: TargetArg) -> &'static str {
    match t {
        TargetArg::Rgba8 => "rgba8",
        TargetArg::Float => "rgba32f",
    }
}

/// The CPU's model name (Linux's `/proc/cpuinfo`), else the architecture.
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// The instruction set the rasterizer's tiles and the sampler's batch kernels run on (run-time
/// dispatch, see
/// `texel::raster::simd_level`).
fn simd_level() -> String {
    format!("{}, run-time dispatch", texel::raster::simd_level().name())
}
