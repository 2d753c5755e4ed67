//! Committed reference images: every built-in scene, small, through every path that makes its
//! pixels, compared byte for byte with the PNGs under `tests/images/`.
//!
//! One contact sheet per scene (`tests/images/NAME.png`), a grid of [`TILE`]-sized tiles in the
//! order of [`tiles`]: the thirteen filters in sRGB; the six debug views; the four core filters
//! with `--precision gpu` (8-bit fixed-point weights), trilinear with quad derivatives, nearest
//! and trilinear in raw colour; a 16-sample reference. Tiles are rendered as `texel render`
//! renders them (the scene prepared at the tile's size, a debug view into an sRGB target) and
//! compared exactly: each of these paths is deterministic, so any change of a pixel is a change
//! of the product, which a refactor must not make.
//!
//! On a mismatch the actual sheet is written beside the expected one as `NAME.actual.png` and
//! the test names every tile that differs. After a change that is meant to change pixels, run
//! with `TEXEL_BLESS=1` to rewrite the sheets, and look at the difference before committing.
//!
//! A second test checks that textures decoded once to `f32` (`--texture-storage float`) render
//! the same bytes as stored 8-bit textures, for every built-in scene, ten filters and both colour
//! handlings.

use std::path::PathBuf;

use texel::quality::Image8;
use texel::raster::{Derivatives, Precision, ReferencePlan};
use texel::{
    ColorHandling, Filter, MemoryBudget, PreparedScene, ReferenceRun, Scene, SceneOptions,
    TextureStorage, View,
};

/// Each tile's size in pixels.
const TILE: (u32, u32) = (64, 36);

/// Tiles per row of a sheet.
const COLUMNS: u32 = 8;

/// One tile: how the scene is prepared and drawn.
#[derive(Clone, Copy, Debug)]
struct Tile {
    /// Names the tile in a mismatch report.
    label: &'static str,
    filter: Option<Filter>,
    view: View,
    color: ColorHandling,
    precision: Precision,
    derivatives: Derivatives,
    storage: TextureStorage,
    /// A 16-sample reference instead of a filtered frame.
    reference: bool,
}

impl Tile {
    fn filter(label: &'static str, filter: Filter) -> Self {
        Tile {
            label,
            filter: Some(filter),
            view: View::Color,
            color: ColorHandling::Srgb,
            precision: Precision::Exact,
            derivatives: Derivatives::Analytic,
            storage: TextureStorage::Stored,
            reference: false,
        }
    }
}

/// Every tile of a sheet, in order.
fn tiles() -> Vec<Tile> {
    let mut out: Vec<Tile> = Filter::ALL
        .iter()
        .map(|&f| Tile::filter(f.name(), f))
        .collect();
    for (label, view) in [
        ("view uv", View::Uv),
        ("view mip", View::Mip),
        ("view lod", View::Lod),
        ("view aniso", View::Aniso),
        ("view fetches", View::Fetches),
        ("view barycentric", View::Barycentric),
    ] {
        out.push(Tile {
            view,
            ..Tile::filter(label, Filter::Trilinear)
        });
    }
    for (label, f) in [
        ("gpu nearest", Filter::Nearest),
        ("gpu bilinear", Filter::Bilinear),
        ("gpu mip-nearest", Filter::MipNearest),
        ("gpu trilinear", Filter::Trilinear),
    ] {
        out.push(Tile {
            precision: Precision::Gpu,
            ..Tile::filter(label, f)
        });
    }
    out.push(Tile {
        derivatives: Derivatives::Quad,
        ..Tile::filter("quad trilinear", Filter::Trilinear)
    });
    for (label, f) in [
        ("raw nearest", Filter::Nearest),
        ("raw trilinear", Filter::Trilinear),
    ] {
        out.push(Tile {
            color: ColorHandling::Raw,
            ..Tile::filter(label, f)
        });
    }
    out.push(Tile {
        reference: true,
        ..Tile::filter("reference 16 spp", Filter::Trilinear)
    });
    out
}

/// Every built-in scene: the unlit ones, then the lit ones.
fn scenes() -> Vec<&'static str> {
    let mut names = texel::scene::builtin_names().to_vec();
    names.extend(texel::scene::shaded_builtin_names());
    names
}

/// A scene prepared once for each colour handling, precision and texture storage its tiles ask
/// for (preparing a lit scene bakes its environment, which costs more than a small frame).
struct Prepared {
    scene: Scene,
    done: Vec<((ColorHandling, Precision, TextureStorage), PreparedScene)>,
}

impl Prepared {
    fn new(name: &str) -> Self {
        Prepared {
            scene: Scene::load(&format!("builtin:{name}")).unwrap(),
            done: Vec::new(),
        }
    }

    /// The scene prepared for `tile`, at the tile's size, as `texel render` prepares it.
    fn get(&mut self, tile: &Tile) -> &PreparedScene {
        let key = (tile.color, tile.precision, tile.storage);
        let at = match self.done.iter().position(|(k, _)| *k == key) {
            Some(at) => at,
            None => {
                let options = SceneOptions {
                    size: Some(TILE),
                    color: tile.color,
                    precision: tile.precision,
                    texture_storage: tile.storage,
                    ..SceneOptions::default()
                };
                let mut budget = MemoryBudget::limit_or_default(None);
                let prepared =
                    PreparedScene::new(self.scene.clone(), &options, &mut budget).unwrap();
                self.done.push((key, prepared));
                self.done.len() - 1
            }
        };
        &self.done[at].1
    }
}

/// The tile's image of the scene.
fn render_tile(scene: &mut Prepared, tile: &Tile) -> Image8 {
    let prepared = scene.get(tile);
    if tile.reference {
        let run = ReferenceRun {
            plan: ReferencePlan {
                min_spp: 16,
                max_spp: 16,
                srgb_display: tile.color == ColorHandling::Srgb,
                ..ReferencePlan::default()
            },
            ..ReferenceRun::default()
        };
        let estimate = prepared.reference(&prepared.scene.camera, &run).unwrap();
        return texel::frame_image(&estimate.frame, tile.color.encoding()).unwrap();
    }
    let mut budget = MemoryBudget::limit_or_default(None);
    let plan = prepared.plan(tile.filter, &mut budget).unwrap();
    let options = texel::FrameOptions {
        view: tile.view,
        derivatives: tile.derivatives,
        ..texel::FrameOptions::default()
    };
    let (frame, encoding) = plan.render(&options).unwrap();
    texel::frame_image(&frame, encoding).unwrap()
}

/// The tiles laid out `COLUMNS` to a row, black between none (tiles abut).
fn sheet(images: &[Image8]) -> Image8 {
    let (tw, th) = TILE;
    let rows = (images.len() as u32).div_ceil(COLUMNS);
    let (w, h) = (tw * COLUMNS, th * rows);
    let mut pixels = vec![[0u8; 4]; (w * h) as usize];
    for (i, image) in images.iter().enumerate() {
        assert_eq!((image.width(), image.height()), TILE);
        let (x0, y0) = ((i as u32 % COLUMNS) * tw, (i as u32 / COLUMNS) * th);
        for y in 0..th {
            let src = &image.pixels()[(y * tw) as usize..((y + 1) * tw) as usize];
            let at = ((y0 + y) * w + x0) as usize;
            pixels[at..at + tw as usize].copy_from_slice(src);
        }
    }
    Image8::new(w, h, pixels).unwrap()
}

/// The tiles of `sheet` (laid out as [`sheet`] lays them) whose pixels differ from `other`'s.
fn differing_tiles(a: &Image8, b: &Image8, count: usize) -> Vec<usize> {
    let (tw, th) = TILE;
    let w = a.width();
    (0..count)
        .filter(|&i| {
            let (x0, y0) = ((i as u32 % COLUMNS) * tw, (i as u32 / COLUMNS) * th);
            (0..th).any(|y| {
                let at = ((y0 + y) * w + x0) as usize;
                a.pixels()[at..at + tw as usize] != b.pixels()[at..at + tw as usize]
            })
        })
        .collect()
}

fn images_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/images")
}

#[test]
fn built_in_scenes_match_their_reference_images() {
    let bless = std::env::var_os("TEXEL_BLESS").is_some_and(|v| v == "1");
    let tiles = tiles();
    let dir = images_dir();
    let mut failures = Vec::new();
    for name in scenes() {
        let mut scene = Prepared::new(name);
        let images: Vec<Image8> = tiles.iter().map(|t| render_tile(&mut scene, t)).collect();
        let actual = sheet(&images);
        let expected_path = dir.join(format!("{name}.png"));
        let actual_path = dir.join(format!("{name}.actual.png"));
        if bless {
            std::fs::create_dir_all(&dir).unwrap();
            actual.write_png(&expected_path).unwrap();
            let _ = std::fs::remove_file(&actual_path);
            continue;
        }
        let expected = match Image8::load(&expected_path) {
            Ok(image) => image,
            Err(e) => {
                actual.write_png(&actual_path).unwrap();
                failures.push(format!(
                    "{name}: cannot read {}: {e}",
                    expected_path.display()
                ));
                continue;
            }
        };
        if (expected.width(), expected.height()) != (actual.width(), actual.height()) {
            actual.write_png(&actual_path).unwrap();
            failures.push(format!(
                "{name}: the sheet is {}x{}, the committed one {}x{} (the tile list changed: bless)",
                actual.width(),
                actual.height(),
                expected.width(),
                expected.height()
            ));
            continue;
        }
        let differ = differing_tiles(&expected, &actual, tiles.len());
        if differ.is_empty() {
            let _ = std::fs::remove_file(&actual_path);
        } else {
            actual.write_png(&actual_path).unwrap();
            let labels: Vec<&str> = differ.iter().map(|&i| tiles[i].label).collect();
            failures.push(format!(
                "{name}: {} tiles differ ({}); actual sheet: {}",
                differ.len(),
                labels.join(", "),
                actual_path.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} scenes differ from tests/images:\n{}",
        failures.len(),
        scenes().len(),
        failures.join("\n")
    );
}

#[test]
fn float_storage_renders_the_stored_textures_bytes() {
    // Every filter but aniso4 and aniso8, which differ from aniso2 and aniso16 only in their
    // probe clamp.
    let filters = Filter::ALL
        .into_iter()
        .filter(|f| !matches!(f, Filter::Aniso4 | Filter::Aniso8));
    let mut differ = Vec::new();
    let mut pairs = 0;
    for name in scenes() {
        let mut scene = Prepared::new(name);
        for filter in filters.clone() {
            for color in [ColorHandling::Srgb, ColorHandling::Raw] {
                let stored = Tile {
                    color,
                    ..Tile::filter("stored", filter)
                };
                let float = Tile {
                    storage: TextureStorage::Float,
                    ..stored
                };
                pairs += 1;
                if render_tile(&mut scene, &stored).pixels()
                    != render_tile(&mut scene, &float).pixels()
                {
                    differ.push(format!("{name} {} {color:?}", filter.name()));
                }
            }
        }
    }
    assert!(
        differ.is_empty(),
        "{} of {pairs} pairs differ: {}",
        differ.len(),
        differ.join("; ")
    );
}
