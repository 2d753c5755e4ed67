//! Grading one mode on one scene: texel's own mode under either convention, evaluated on exactly
//! what the student's shader received (the device's interpolated coordinate and its 2x2-quad
//! derivatives, [`crate::gl::Capture`]), compared pixel by pixel with the shader's frame.
//!
//! **The agreement measure.** The share of covered pixels whose R, G and B each lie within
//! [`AGREE_CODES`] codes of texel's; a mode gets the verdict of a convention when that share is at
//! least [`AGREE_SHARE`]. Equal inputs leave only arithmetic between the two: the order of the
//! lerps, fused multiply-adds, and the rare pixel whose index or level sits on a rounding edge
//! (a few pixels a frame, along texel and level boundaries). A half-texel mistake moves every
//! magnified pixel and every texel edge, and a level mistake every minified pixel, far past both
//! limits (docs/decisions.md, "The lab's agreement measure", has the figures).
//!
//! **Diagnosis.** For a mode that agrees with neither convention, each likely mistake
//! ([`MUTANTS`]: a convention's [`Rules`] one knob away) is evaluated the same way and the best
//! match named; mistakes that show only in one class of pixels (magnified, anisotropy 1,
//! negative coordinates) are found by the agreement inside and outside that class.

use rayon::prelude::*;
use texel_texture::technique::lab::{AnisoLevel, Count, LevelAxis, NearestLevel, Wrap};
use texel_texture::{Convention, Footprint, Rules};

use crate::gl::Capture;
use crate::scene::LabScene;

/// Codes per channel within which a pixel agrees.
pub const AGREE_CODES: u8 = 6;
/// The share of covered pixels that must agree for a convention's verdict.
pub const AGREE_SHARE: f64 = 0.97;

/// A mode's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Agrees with texel's mode under the OpenGL / Vulkan rules.
    Gl,
    /// Agrees with texel's mode under the lab handout's formulas.
    Lab,
    /// Agrees with neither.
    Neither,
}

/// A likely mistake: a convention's rules with one thing changed.
pub struct Mutant {
    /// Short key (`half-texel`).
    pub key: &'static str,
    /// What the student likely did.
    pub text: &'static str,
    /// The modes the mistake shows in.
    pub modes: &'static [u8],
    /// The rules it produces from a convention's.
    pub apply: fn(Rules) -> Rules,
}

const ALL: &[u8] = &[1, 2, 3, 4, 5, 6, 7, 8];
const FILTERED: &[u8] = &[2, 3, 4, 5, 6, 7, 8];
const MIPPED: &[u8] = &[3, 4, 5, 6, 7, 8];
const BLENDED: &[u8] = &[4, 5, 6, 7, 8];
const ANISO: &[u8] = &[5, 6, 7, 8];

/// The mistakes the diagnosis knows, each applied to both conventions.
pub const MUTANTS: &[Mutant] = &[
    Mutant {
        key: "half-texel",
        text: "half-texel offset: the texel indices taken from x - 0.5 where the rules take x (for example floor(x - 0.5) for nearest, or texel centres at +1 for bilinear)",
        modes: ALL,
        apply: |r| shift(r, -0.5),
    },
    Mutant {
        key: "half-texel",
        text: "half-texel offset: the texel indices taken from x + 0.5 where the rules take x (for example floor(x + 0.5) for bilinear's first tap)",
        modes: ALL,
        apply: |r| shift(r, 0.5),
    },
    Mutant {
        key: "half-texel",
        text: "half-texel offset of the wrong sign: + 0.5 where the rules take - 0.5 (or the reverse), which moves every texel index by one",
        modes: ALL,
        apply: |r| shift(r, 1.0),
    },
    Mutant {
        key: "half-texel",
        text: "half-texel offset of the wrong sign: + 0.5 where the rules take - 0.5 (or the reverse), which moves every texel index by one",
        modes: ALL,
        apply: |r| shift(r, -1.0),
    },
    Mutant {
        key: "weights-offset",
        text: "half-texel offset between taps and weights: the four texels from one texel-centre rule, the weights fract() from the other",
        modes: FILTERED,
        apply: |r| Rules {
            weight_offset: 0.5 - r.weight_offset,
            ..r
        },
    },
    Mutant {
        key: "level-floor",
        text: "mip level rounded down: mode 3 reads the finer level [N] instead of the nearest (GL) or the coarser ]N[ (lab)",
        modes: &[3],
        apply: |r| Rules {
            nearest_level: NearestLevel::Finer,
            ..r
        },
    },
    Mutant {
        key: "shorter-derivative",
        text: "level from the shorter derivative: N from min(|Px|, |Py|) instead of the max, which aliases where the footprint is anisotropic",
        modes: &[3, 4],
        apply: |r| Rules {
            level_axis: LevelAxis::Shorter,
            ..r
        },
    },
    Mutant {
        key: "blend-reversed",
        text: "mip blend reversed: the weight N - [N] given to the finer level instead of the coarser",
        modes: BLENDED,
        apply: |r| Rules {
            blend_reversed: true,
            ..r
        },
    },
    Mutant {
        key: "probe-span-double",
        text: "probes over the wrong span: spread over 2 Pmax instead of Pmax",
        modes: ANISO,
        apply: |r| Rules { span: 2.0, ..r },
    },
    Mutant {
        key: "probe-span-half",
        text: "probes over the wrong span: spread over Pmax / 2 instead of Pmax",
        modes: ANISO,
        apply: |r| Rules { span: 0.5, ..r },
    },
    Mutant {
        key: "aniso-level-major",
        text: "anisotropic level from the longer axis |Pmax| instead of the shorter: as blurry as trilinear",
        modes: ANISO,
        apply: |r| Rules {
            aniso_level: AnisoLevel::Major,
            ..r
        },
    },
    Mutant {
        key: "negative-indices",
        text: "negative indices not wrapped: GLSL's % keeps the sign of a negative operand (the result is undefined), so texelFetch reads outside the level",
        modes: ALL,
        apply: |r| Rules {
            wrap: Wrap::Truncated,
            ..r
        },
    },
    Mutant {
        key: "no-wrap",
        text: "indices not wrapped: texelFetch does not repeat the texture, so every index outside the level reads zero (wrap with i - n * floor(i / n))",
        modes: ALL,
        apply: |r| Rules {
            wrap: Wrap::None,
            ..r
        },
    },
    Mutant {
        key: "level-clamp",
        text: "wrong level clamp: N not clamped to [0, M], so magnified pixels (N < 0) read a level that does not exist",
        modes: MIPPED,
        apply: |r| Rules {
            clamp_level: false,
            ..r
        },
    },
];

/// `r` with every texel-centre offset moved by `d` texels.
fn shift(r: Rules, d: f32) -> Rules {
    Rules {
        nearest_offset: r.nearest_offset + d,
        bilinear_offset: r.bilinear_offset - d,
        weight_offset: r.weight_offset - d,
        ..r
    }
}

/// The handout leaves the probe count of a non-integer anisotropy open: each of these counts
/// is the lab's formula.
const LAB_COUNTS: [Count; 3] = [Count::Ceil, Count::Round, Count::Floor];

/// texel's frame of `mode` under `rules` on what the device captured, RGBA8 (raw colour), with
/// the texels read; uncovered pixels keep the shader's value so they never differ.
pub fn evaluate(
    scene: &LabScene,
    capture: &Capture,
    mode: u8,
    rules: &Rules,
) -> (Vec<[u8; 4]>, u64) {
    let draws = scene.draws();
    let px: Vec<([u8; 4], u32)> = capture
        .uv_dx
        .par_iter()
        .zip(&capture.dy_draw)
        .map(|(a, b)| {
            let id = b[2].round() as usize;
            let Some(d) = id.checked_sub(1).and_then(|k| draws.get(k)) else {
                return ([0; 4], 0);
            };
            let fp = Footprint {
                u: a[0],
                v: a[1],
                dudx: a[2],
                dvdx: a[3],
                dudy: b[0],
                dvdy: b[1],
            };
            let (c, n) = d
                .texture
                .sample_rules(&d.sampler.address(), mode, rules, &fp);
            (c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8), n)
        })
        .collect();
    let reads = px.iter().map(|p| u64::from(p.1)).sum();
    (px.into_iter().map(|p| p.0).collect(), reads)
}

/// Whether a pixel is covered in the capture.
pub fn covered(capture: &Capture) -> Vec<bool> {
    capture.dy_draw.iter().map(|b| b[2] > 0.5).collect()
}

/// The share of `mask`'s pixels where `a` and `b` agree within [`AGREE_CODES`] in R, G and B (1
/// for an empty mask).
pub fn agreement(a: &[[u8; 4]], b: &[[u8; 4]], mask: &[bool]) -> f64 {
    let (mut n, mut ok) = (0u64, 0u64);
    for ((x, y), &m) in a.iter().zip(b).zip(mask) {
        if m {
            n += 1;
            if (0..3).all(|k| x[k].abs_diff(y[k]) <= AGREE_CODES) {
                ok += 1;
            }
        }
    }
    if n == 0 {
        1.0
    } else {
        ok as f64 / n as f64
    }
}

/// One convention's best image of a mode: its agreement with the shader and the image.
pub struct Match {
    /// Agreement with the shader's frame.
    pub agreement: f64,
    /// texel's frame.
    pub image: Vec<[u8; 4]>,
    /// Texels read over the frame.
    pub reads: u64,
}

/// texel's mode under `convention` compared with `shader` (for the lab's anisotropic modes, the
/// best of the probe counts the handout allows).
pub fn convention_match(
    scene: &LabScene,
    capture: &Capture,
    mode: u8,
    convention: Convention,
    shader: &[[u8; 4]],
    mask: &[bool],
) -> Match {
    let base = convention.rules();
    let variants: Vec<Rules> = if convention == Convention::Lab && mode >= 5 {
        LAB_COUNTS
            .iter()
            .map(|&count| Rules { count, ..base })
            .collect()
    } else {
        vec![base]
    };
    variants
        .iter()
        .map(|r| {
            let (image, reads) = evaluate(scene, capture, mode, r);
            Match {
                agreement: agreement(shader, &image, mask),
                image,
                reads,
            }
        })
        .max_by(|a, b| a.agreement.total_cmp(&b.agreement))
        .unwrap_or(Match {
            agreement: 0.0,
            image: Vec::new(),
            reads: 0,
        })
}

/// Classes of pixels where a mistake may show alone.
struct Class {
    text: &'static str,
    modes: &'static [u8],
    member: Vec<bool>,
}

fn classes(scene: &LabScene, capture: &Capture) -> Vec<Class> {
    let draws = scene.draws();
    let mut magnified = Vec::new();
    let mut isotropic = Vec::new();
    let mut negative = Vec::new();
    for (a, b) in capture.uv_dx.iter().zip(&capture.dy_draw) {
        let id = b[2].round() as usize;
        let (w, h) = id
            .checked_sub(1)
            .and_then(|k| draws.get(k))
            .map_or((1.0, 1.0), |d| {
                (d.texture.width() as f32, d.texture.height() as f32)
            });
        let px = (a[2] * w).hypot(a[3] * h);
        let py = (b[0] * w).hypot(b[1] * h);
        let (major, minor) = (px.max(py), px.min(py));
        magnified.push(major <= 1.0);
        isotropic.push(major <= minor * 1.0001 + 1e-9 || major / minor < 1.5);
        negative.push(a[0] < 0.0 || a[1] < 0.0);
    }
    vec![
        Class {
            text: "wrong level clamp: the pixels that are magnified (N < 0) are wrong and the others right; clamp N to 0 there",
            modes: MIPPED,
            member: magnified,
        },
        Class {
            text: "anisotropy 1 not handled: the pixels whose footprint is isotropic (lambda = 1, one probe, where i / (lambda - 1) divides by zero) are wrong and the others right",
            modes: ANISO,
            member: isotropic,
        },
        Class {
            text: "negative indices not wrapped: the pixels with negative coordinates are wrong and the others right (GLSL's % is undefined for a negative operand; wrap with ((i % n) + n) % n)",
            modes: ALL,
            member: negative,
        },
    ]
}

/// Likely mistakes of a mode that agrees with neither convention, best first, each with its
/// evidence.
pub fn diagnose(
    scene: &LabScene,
    capture: &Capture,
    mode: u8,
    shader: &[[u8; 4]],
    mask: &[bool],
    (gl, lab): (&Match, &Match),
) -> Vec<String> {
    let mut found: Vec<(f64, String)> = Vec::new();
    for m in MUTANTS.iter().filter(|m| m.modes.contains(&mode)) {
        for c in Convention::ALL {
            let rules = (m.apply)(c.rules());
            if rules == Rules::GL || rules == Rules::LAB {
                continue;
            }
            let (image, _) = evaluate(scene, capture, mode, &rules);
            let a = agreement(shader, &image, mask);
            if a >= AGREE_SHARE {
                found.push((
                    a,
                    format!(
                        "{} [{}; the {} rules with this mistake agree on {:.1} % of pixels]",
                        m.text,
                        m.key,
                        c.name(),
                        100.0 * a
                    ),
                ));
            }
        }
    }
    // A mistake that shows in one class of pixels alone, where no whole-frame mistake matched.
    let classes = if found.is_empty() {
        classes(scene, capture)
    } else {
        Vec::new()
    };
    for class in classes.iter().filter(|c| c.modes.contains(&mode)) {
        for (c, matched) in [(Convention::Gl, gl), (Convention::Lab, lab)] {
            let inside: Vec<bool> = mask
                .iter()
                .zip(&class.member)
                .map(|(m, k)| *m && *k)
                .collect();
            let outside: Vec<bool> = mask
                .iter()
                .zip(&class.member)
                .map(|(m, k)| *m && !*k)
                .collect();
            let n_in = inside.iter().filter(|x| **x).count();
            let n_all = mask.iter().filter(|x| **x).count().max(1);
            if n_in * 100 < n_all {
                continue;
            }
            let a_in = agreement(shader, &matched.image, &inside);
            let a_out = agreement(shader, &matched.image, &outside);
            if a_out >= AGREE_SHARE && a_in < AGREE_SHARE {
                found.push((
                    a_out,
                    format!(
                        "{} [{} rules: {:.1} % of those pixels agree, {:.1} % of the others]",
                        class.text,
                        c.name(),
                        100.0 * a_in,
                        100.0 * a_out
                    ),
                ));
            }
        }
    }
    found.sort_by(|a, b| b.0.total_cmp(&a.0));
    found.dedup_by(|a, b| a.1 == b.1);
    if found.is_empty() {
        let (name, best) = if gl.agreement >= lab.agreement {
            ("gl", gl.agreement)
        } else {
            ("lab", lab.agreement)
        };
        return vec![format!(
            "no single known mistake explains the frame; the closest is the {name} convention, \
             on {:.1} % of pixels",
            100.0 * best
        )];
    }
    found.into_iter().map(|f| f.1).collect()
}

/// The verdict of a mode from the two agreements.
pub fn verdict(gl: f64, lab: f64) -> Verdict {
    if gl.max(lab) < AGREE_SHARE {
        Verdict::Neither
    } else if gl >= lab {
        Verdict::Gl
    } else {
        Verdict::Lab
    }
}
