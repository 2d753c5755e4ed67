//! `texel::compare`: the one comparison the command line, the demo and Python run.

use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

use texel::compare::{compare, CompareJob, Extra, Progress, Stage};
use texel::raster::{ReferencePlan, ReferenceStatus};
use texel::{Error, Filter, MemoryBudget, PreparedScene, Scene, SceneOptions};

fn ground(size: (u32, u32)) -> (PreparedScene, MemoryBudget) {
    let mut budget = MemoryBudget::limit_or_default(None);
    let options = SceneOptions {
        size: Some(size),
        ..SceneOptions::default()
    };
    let scene = Scene::load("builtin:ground").unwrap();
    (
        PreparedScene::new(scene, &options, &mut budget).unwrap(),
        budget,
    )
}

fn plan() -> ReferencePlan {
    ReferencePlan::new(4, 4, 0.5, true, 7).unwrap()
}

/// Records every call, in order.
#[derive(Default)]
struct Log(Mutex<Vec<String>>);

impl Progress for Log {
    fn stage(&self, stage: Stage<'_>) {
        self.0.lock().unwrap().push(format!("begin {stage:?}"));
    }
    fn reference(&self, _: &ReferenceStatus) {}
    fn done(&self, stage: Stage<'_>) {
        self.0.lock().unwrap().push(format!("end {stage:?}"));
    }
}

#[test]
fn rows_scores_and_files() {
    let (scene, mut budget) = ground((48, 27));
    let filters = [Filter::Nearest, Filter::Trilinear];
    let log = Log::default();
    let job = CompareJob {
        progress: Some(&log),
        ..CompareJob::new("ground", &filters, plan())
    };
    job.charge(&scene, &mut budget).unwrap();
    let dir = std::env::temp_dir().join(format!("texel-compare-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let written = compare(&scene, &job, Some(&dir), &mut budget).unwrap();
    let scores_only = compare(&scene, &job, None, &mut budget).unwrap();

    let names: Vec<&str> = written.rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["nearest", "trilinear"]);
    assert_eq!((written.width, written.height, written.spp), (48, 27, 4));
    for (a, b) in written.rows.iter().zip(&scores_only.rows) {
        // The scores do not depend on whether the images are written; the times do.
        assert_eq!(
            (a.psnr_all, a.ssim, a.psnr_block),
            (b.psnr_all, b.ssim, b.psnr_block)
        );
        assert_eq!(a.texels_per_pixel_mean, b.texels_per_pixel_mean);
        assert!(a.ms_per_frame.unwrap() > 0.0);
        // Nearest reads one texel a pixel; trilinear up to eight.
        let texels = a.texels_per_pixel_mean.unwrap();
        assert!((1.0..=8.0).contains(&texels), "{texels}");
        assert!(a.heat_map.is_some() && b.heat_map.is_none());
        assert!(dir.join(&a.image).is_file());
        assert!(dir.join(a.heat_map.as_ref().unwrap()).is_file());
    }
    for file in ["reference.png", "report.json", "report.md", "index.html"] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    // Trilinear is closer to the reference than nearest at the ground's horizon.
    assert!(written.rows[1].psnr_all > written.rows[0].psnr_all);
    let noise = written.reference_error.as_ref().unwrap();
    assert!(written
        .rows
        .iter()
        .all(|r| r.psnr_all <= noise.noise_floor + 1e-9));
    let log = log.0.lock().unwrap();
    assert_eq!(
        log[..6],
        [
            "begin Reference { n: 0, of: 1 }",
            "end Reference { n: 0, of: 1 }",
            "begin Filter(\"nearest\")",
            "end Filter(\"nearest\")",
            "begin Filter(\"trilinear\")",
            "end Filter(\"trilinear\")",
        ]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_extra_frame_scores_as_the_filter_it_is() {
    let (scene, mut budget) = ground((48, 27));
    let plan_trilinear = scene.plan(Some(Filter::Trilinear), &mut budget).unwrap();
    let frame = texel::render(&plan_trilinear.settings(), &plan_trilinear.draws()).unwrap();
    drop(plan_trilinear);
    let extras = [Extra::Frame {
        label: "elsewhere".into(),
        frame,
        ms: 1.5,
    }];
    let filters = [Filter::Trilinear];
    let job = CompareJob {
        extras: &extras,
        ..CompareJob::new("ground", &filters, plan())
    };
    let report = compare(&scene, &job, None, &mut budget).unwrap();
    let (own, extra) = (&report.rows[0], &report.rows[1]);
    assert!(extra.extra && !own.extra);
    assert_eq!(extra.ms_per_frame, Some(1.5));
    assert_eq!((own.psnr_all, own.ssim), (extra.psnr_all, extra.ssim));
    // Identical images cannot be ranked apart.
    assert_eq!(own.within_noise_of, ["elsewhere"]);
}

#[test]
fn a_stop_and_a_frame_too_small_for_ssim_are_errors() {
    let (scene, mut budget) = ground((48, 27));
    let stop = AtomicBool::new(true);
    let filters = [Filter::Nearest];
    let job = CompareJob {
        stop: Some(&stop),
        ..CompareJob::new("ground", &filters, plan())
    };
    assert!(matches!(
        compare(&scene, &job, None, &mut budget),
        Err(Error::Cancelled)
    ));
    let (small, mut budget) = ground((8, 8));
    let job = CompareJob::new("ground", &filters, plan());
    let err = compare(&small, &job, None, &mut budget).unwrap_err();
    assert!(matches!(err, Error::Compare(_)), "{err}");
    assert!(err.to_string().contains("SSIM"), "{err}");
}

#[test]
fn plans_are_checked_once_for_every_face() {
    let p = ReferencePlan::new(16, 64, 0.5, false, 3).unwrap();
    assert_eq!((p.min_spp, p.max_spp, p.seed), (16, 64, 3));
    assert_eq!(p.tolerance, 0.5 / 255.0);
    assert_eq!(p.tolerance_steps(), 0.5);
    assert!(!p.srgb_display);
    let below = ReferencePlan::new(64, 16, 0.5, true, 0).unwrap_err();
    assert!(
        below.to_string().contains("max_spp 16 is below spp 64"),
        "{below}"
    );
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let e = ReferencePlan::new(4, 4, bad, true, 0).unwrap_err();
        assert!(e.to_string().contains("tolerance must be"), "{e}");
    }
    assert!(ReferencePlan::new(0, 4, 0.5, true, 0).is_err());
    assert!(ReferencePlan::new(4, u32::MAX, 0.5, true, 0).is_err());
}
