//! `texel lab`: a student's shader rendered in a child process with a time limit
//! ([`texel::lab::run_device`] under `texel lab-device`), then graded ([`texel::lab::grade`]) and
//! the report published into `--out`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use texel::lab::{self, Job, Names};

use crate::cli::LabArgs;
use crate::input::Input;

/// The device's work folder: inside the report's staging directory (so a signal's clean-up
/// removes it with the rest, and it is never published), private to this user, removed when
/// dropped.
struct WorkDir(PathBuf);

impl WorkDir {
    fn new(staging: &Path) -> Result<WorkDir> {
        use std::os::unix::fs::DirBuilderExt;
        let dir = staging.join(".device");
        std::fs::DirBuilder::new()
            .mode(0o700)
            .create(&dir)
            .with_context(|| format!("cannot make {}", dir.display()))?;
        Ok(WorkDir(dir))
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Bytes one scene costs the lab at `w x h` with `modes` modes: the capture (32 a pixel) and a
/// frame per mode (4) on disk and in memory, and the report's images (the shader's, texel's and
/// the heat map per mode, and the reference: 4 bytes a pixel each) with texel's evaluations
/// (twice 4 a pixel per mode while grading).
fn scene_bytes(w: u32, h: u32, modes: usize) -> u64 {
    let px = u64::from(w) * u64::from(h);
    px.saturating_mul(32 + 4 + 4 * (1 + 3 * modes as u64) + 8 * modes as u64)
}

/// Run `texel lab`.
pub(crate) fn run(args: &LabArgs, input: &mut Input) -> Result<()> {
    let fragment = lab::read_shader(&args.shader, "fragment shader")?;
    let vertex = match &args.vertex {
        Some(p) => Some(lab::read_shader(p, "vertex shader")?),
        None => None,
    };
    let mut job = Job::new(fragment);
    job.vertex = vertex;
    job.names = Names {
        sampler: args.sampler.clone(),
        mode: args.mode_uniform.clone(),
        varying: args.varying.clone(),
    };
    if !args.scenes.is_empty() {
        job.scenes = args.scenes.clone();
    }
    job.modes = args.modes.0.clone();
    job.frames = args.frames as usize;
    job.size = args.size.map(|s| (s.width, s.height));
    // Scenes are checked here, before the device starts, so a bad one is reported as such, and
    // what the lab keeps of each is charged to the memory budget.
    for s in &job.scenes {
        let scene = lab::LabScene::load(s, job.size)?;
        let (w, h) = scene.size();
        input.budget.take(
            &format!("the lab's capture, frames and images of {s}"),
            scene_bytes(w, h, job.modes.len()),
        )?;
    }
    for v in lab::violations(&job.fragment) {
        texel_io::stderr_line(format_args!(
            "texel: warning: line {}: `{}` breaks the lab's rule (texelFetch and textureSize only); the shader is still graded, and marked",
            v.line, v.call
        ));
    }
    for line in lab::level_size_queries(&job.fragment) {
        texel_io::stderr_line(format_args!(
            "texel: note: line {line} asks textureSize for a per-pixel level; Mesa's llvmpipe answers one size for a whole quad, so use max(textureSize(texSlot, 0) >> level, ivec2(1))"
        ));
    }
    let shader_name = texel_io::escape(&args.shader.display().to_string()).into_owned();
    let options = lab::GradeOptions {
        reference_spp: args.spp,
        threads: args.threads.map(|t| t as usize),
    };
    // What the command reads must not lie inside what it replaces.
    let mut inputs: Vec<&Path> = vec![args.shader.as_path()];
    if let Some(v) = &args.vertex {
        inputs.push(v);
    }
    inputs.extend(
        job.scenes
            .iter()
            .map(Path::new)
            .filter(|p| p.extension().is_some()),
    );
    let limit = Duration::from_secs(args.timeout);
    let report = texel_io::publish_dir(&args.out, &inputs, |dir| {
        let work = WorkDir::new(dir)?;
        let job_path = work.0.join("job.json");
        std::fs::write(&job_path, serde_json::to_vec(&job)?)
            .with_context(|| format!("cannot write {}", job_path.display()))?;
        device_in_child(&work.0, limit)?;
        let (report, images) = texel::raster::on_threads(options.threads, || {
            lab::grade(&job, &shader_name, &work.0, &options)
        })??;
        drop(work);
        report.write(&images, dir)?;
        Ok::<_, anyhow::Error>(report)
    })
    .with_context(|| format!("cannot write the report to {}", args.out.display()))?;
    let mut summary = format!("score {:.1} / 100\n", report.score);
    for m in &report.modes {
        summary.push_str(&format!(
            "{:<12} mode {}  {:<7}  gl {:5.1} %  lab {:5.1} %  {:5.1} dB\n",
            m.scene,
            m.mode,
            match m.verdict {
                lab::Verdict::Gl => "gl",
                lab::Verdict::Lab => "lab",
                lab::Verdict::Neither => "neither",
            },
            100.0 * m.agreement_gl,
            100.0 * m.agreement_lab,
            m.psnr_reference
        ));
        for d in &m.diagnosis {
            summary.push_str(&format!("    {d}\n"));
        }
    }
    texel_io::stdout_text(&summary).context(crate::cmd_render::STDOUT)?;
    texel_io::stderr_line(format_args!(
        "report: {}",
        args.out.join("report.html").display()
    ));
    Ok(())
}

/// Run `texel lab-device DIR` and wait at most `limit`; a child still running then is killed.
fn device_in_child(dir: &Path, limit: Duration) -> Result<()> {
    let exe = std::env::current_exe().context("cannot find the texel executable")?;
    use std::os::unix::process::CommandExt;
    let log =
        std::fs::File::create(dir.join("stderr.txt")).context("cannot make the device's log")?;
    // A process group of its own: Ctrl-C reaches texel, which stops the child itself.
    let mut child = Command::new(exe)
        .arg("lab-device")
        .arg(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log)
        .process_group(0)
        .spawn()
        .context("cannot start the device process")?;
    let start = Instant::now();
    let graceful = crate::interrupt::Graceful::begin();
    let status = loop {
        if let Some(status) = child
            .try_wait()
            .context("cannot wait for the device process")?
        {
            break status;
        }
        if graceful.flag().load(std::sync::atomic::Ordering::SeqCst) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(crate::interrupt::Interrupted(
                "the lab was interrupted before grading".into(),
            )
            .into());
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "the shader did not finish within {} s and was stopped (an endless loop, or a frame too slow: --timeout sets the limit)",
                limit.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    if status.success() {
        return Ok(());
    }
    // The driver's log on one line, as every texel error is.
    let log = std::fs::read_to_string(dir.join("error.txt"))
        .unwrap_or_else(|_| format!("the device process ended with {status}"));
    let line: Vec<&str> = log
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    bail!("{}", line.join(" "))
}

/// `texel lab-device DIR`: render the job in `DIR/job.json` into `DIR`; on failure write the
/// message to `DIR/error.txt`.
pub(crate) fn device(dir: &Path) -> Result<()> {
    let text = std::fs::read_to_string(dir.join("job.json"))
        .with_context(|| format!("cannot read {}", dir.join("job.json").display()))?;
    let job: Job = serde_json::from_str(&text).context("the job file is not valid")?;
    if let Err(e) = lab::run_device(&job, dir) {
        let _ = std::fs::write(dir.join("error.txt"), e.to_string());
        return Err(e.into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::cli::parse_modes;

    #[test]
    fn mode_lists() {
        assert_eq!(parse_modes("1-8").unwrap().0, (1..=8).collect::<Vec<u8>>());
        assert_eq!(parse_modes("5, 1-2,2").unwrap().0, vec![1, 2, 5]);
        assert!(parse_modes("0").is_err());
        assert!(parse_modes("9").is_err());
        assert!(parse_modes("4-2").is_err());
        assert!(parse_modes("").is_err());
    }
}
