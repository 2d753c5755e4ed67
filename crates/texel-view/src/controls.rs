//! The viewer's keys and the state they change: one table ([`KEYS`]) for `--help`, the overlay and
//! the tests; one function ([`ViewState::apply`]) from a key press to the new state. No window is
//! needed here: `--keys` scripts and the window's keyboard both arrive as [`Press`]es.

use texel::raster::{Derivatives, Perspective, View};
use texel::Filter;

/// What one half of the screen (or the whole screen) shows: a filter, or the progressive
/// supersampled reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Mode {
    /// Texture filter for every mesh.
    Filter(Filter),
    /// The reference: jittered level-0 sub-samples accumulated while the camera is still.
    Reference,
}

impl Mode {
    /// Short name for the HUD and file names.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Mode::Filter(f) => f.name(),
            Mode::Reference => "reference",
        }
    }
}

/// A key, independent of the keyboard layout (winit's physical keys map onto it) and of where it
/// came from (the window or a `--keys` script).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Key {
    /// `0` to `9`.
    Digit(u8),
    /// `a` to `z` (lower case).
    Letter(char),
    /// Tab.
    Tab,
    /// Escape.
    Escape,
    /// F12.
    F12,
    /// `[`.
    BracketLeft,
    /// `]`.
    BracketRight,
    /// Arrow left.
    Left,
    /// Arrow right.
    Right,
    /// Arrow up.
    Up,
    /// Arrow down.
    Down,
    /// Page up.
    PageUp,
    /// Page down.
    PageDown,
}

/// A key press with the state of Shift.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Press {
    /// The key.
    pub(crate) key: Key,
    /// Whether Shift was held.
    pub(crate) shift: bool,
}

/// One row of the key table: the keys, what they do.
pub(crate) struct KeyHelp {
    /// The keys as the user types them.
    pub keys: &'static str,
    /// What they do.
    pub action: &'static str,
}

/// Every key of `texel view`, as `--help` and the overlay (H) show them.
pub(crate) const KEYS: &[KeyHelp] = &[
    KeyHelp {
        keys: "1-8",
        action: "the lab's modes: nearest, bilinear, mip-nearest, trilinear, aniso2-16",
    },
    KeyHelp {
        keys: "9 / 0",
        action: "EWA / the reference (accumulates up to 512 samples per pixel while still)",
    },
    KeyHelp {
        keys: "E B M T",
        action: "EWA from weighted probes, bicubic, ripmap, summed-area table",
    },
    KeyHelp {
        keys: "Shift+key",
        action: "any filter key above: the right half's filter (turns split screen on)",
    },
    KeyHelp {
        keys: "Tab",
        action: "split screen on/off; drag the divider with the mouse",
    },
    KeyHelp {
        keys: "V / Shift+V",
        action: "next / previous view: colour, uv, mip, lod, aniso, fetches, barycentric",
    },
    KeyHelp {
        keys: "P",
        action: "perspective-correct / affine interpolation",
    },
    KeyHelp {
        keys: "Q",
        action: "analytic / 2x2 quad derivatives",
    },
    KeyHelp {
        keys: "[ ]",
        action: "lod bias -0.5 / +0.5",
    },
    KeyHelp {
        keys: "C",
        action: "sRGB / raw colour",
    },
    KeyHelp {
        keys: "WASD, arrows",
        action: "move (Shift: 4x faster); PageUp/PageDown: up/down",
    },
    KeyHelp {
        keys: "mouse drag, scroll",
        action: "look around; field of view",
    },
    KeyHelp {
        keys: "R",
        action: "back to the scene's camera",
    },
    KeyHelp {
        keys: "H",
        action: "this help",
    },
    KeyHelp {
        keys: "F12",
        action: "screenshot: a PNG named after the state",
    },
    KeyHelp {
        keys: "Esc",
        action: "quit",
    },
];

/// The key table as plain text, one row a line (for `--help`).
pub fn key_table() -> String {
    let width = KEYS.iter().map(|k| k.keys.len()).max().unwrap_or(0);
    let mut s = String::from("Keys:\n");
    for k in KEYS {
        s.push_str(&format!("  {:width$}  {}\n", k.keys, k.action));
    }
    s
}

/// Every state a frame depends on except the camera.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ViewState {
    /// The whole screen's mode, or the left half's in split screen.
    pub left: Mode,
    /// The right half's mode in split screen.
    pub right: Mode,
    /// Split screen on.
    pub split: bool,
    /// The divider's position as a fraction of the width, in `[0.05, 0.95]`.
    pub divider: f32,
    /// What each pixel shows.
    pub view: View,
    /// Attribute interpolation.
    pub perspective: Perspective,
    /// Where uv derivatives come from.
    pub derivatives: Derivatives,
    /// Added to every sampler's lod (`SamplerDescriptor::lod_bias`), in `[-MAX_BIAS, MAX_BIAS]`.
    pub lod_bias: f32,
    /// Colour handling of textures and output.
    pub color: texel::ColorHandling,
    /// Heads-up display (and the divider line) shown.
    pub hud: bool,
    /// The key table shown.
    pub help: bool,
}

/// The largest lod bias `[` and `]` reach, in levels.
pub(crate) const MAX_BIAS: f32 = 8.0;

/// What a key press asks of the viewer besides a new state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Effect {
    /// Nothing (or only the state changed).
    None,
    /// Write a screenshot.
    Screenshot,
    /// Quit.
    Quit,
    /// Move the camera back to the scene's.
    ResetCamera,
    /// A movement key: handled by the camera (held keys move it while held).
    Move,
}

impl ViewState {
    /// The start: `mode` on the whole screen (trilinear on the right when split), colour view,
    /// perspective-correct, analytic derivatives, no bias, HUD on.
    pub(crate) fn new(mode: Mode, color: texel::ColorHandling) -> ViewState {
        ViewState {
            left: mode,
            right: Mode::Filter(Filter::Trilinear),
            split: false,
            divider: 0.5,
            view: View::Color,
            perspective: Perspective::Correct,
            derivatives: Derivatives::Analytic,
            lod_bias: 0.0,
            color,
            hud: true,
            help: false,
        }
    }

    /// The modes on screen: one, or left and right in split screen.
    pub(crate) fn modes(&self) -> Vec<Mode> {
        if self.split {
            vec![self.left, self.right]
        } else {
            vec![self.left]
        }
    }

    /// Apply one key press; see [`KEYS`].
    pub(crate) fn apply(&mut self, press: Press) -> Effect {
        if let Some(mode) = mode_of(press.key) {
            if press.shift {
                self.right = mode;
                self.split = true;
            } else {
                self.left = mode;
            }
            return Effect::None;
        }
        match press.key {
            Key::Tab => self.split = !self.split,
            Key::Letter('v') => {
                let k = View::ALL.iter().position(|&v| v == self.view).unwrap_or(0);
                let n = View::ALL.len();
                self.view = View::ALL[if press.shift {
                    (k + n - 1) % n
                } else {
                    (k + 1) % n
                }];
            }
            Key::Letter('p') => {
                self.perspective = match self.perspective {
                    Perspective::Correct => Perspective::Affine,
                    Perspective::Affine => Perspective::Correct,
                }
            }
            Key::Letter('q') => {
                self.derivatives = match self.derivatives {
                    Derivatives::Analytic => Derivatives::Quad,
                    Derivatives::Quad => Derivatives::Analytic,
                }
            }
            Key::BracketLeft => self.lod_bias = (self.lod_bias - 0.5).max(-MAX_BIAS),
            Key::BracketRight => self.lod_bias = (self.lod_bias + 0.5).min(MAX_BIAS),
            Key::Letter('c') => {
                self.color = match self.color {
                    texel::ColorHandling::Srgb => texel::ColorHandling::Raw,
                    texel::ColorHandling::Raw => texel::ColorHandling::Srgb,
                }
            }
            Key::Letter('h') => self.help = !self.help,
            Key::F12 => return Effect::Screenshot,
            Key::Escape => return Effect::Quit,
            Key::Letter('r') => return Effect::ResetCamera,
            Key::Letter('w' | 'a' | 's' | 'd')
            | Key::Left
            | Key::Right
            | Key::Up
            | Key::Down
            | Key::PageUp
            | Key::PageDown => return Effect::Move,
            _ => {}
        }
        Effect::None
    }

    /// A file name that says the state: `texel-aniso16-color.png`,
    /// `texel-trilinear-vs-ewa-mip-affine-quad-bias+1.0-raw.png`; non-default settings only.
    pub(crate) fn file_name(&self) -> String {
        let mut s = format!("texel-{}", self.left.name());
        if self.split {
            s.push_str(&format!("-vs-{}", self.right.name()));
        }
        s.push('-');
        s.push_str(self.view.name());
        if self.perspective == Perspective::Affine {
            s.push_str("-affine");
        }
        if self.derivatives == Derivatives::Quad {
            s.push_str("-quad");
        }
        if self.lod_bias != 0.0 {
            s.push_str(&format!("-bias{:+.1}", self.lod_bias));
        }
        if self.color == texel::ColorHandling::Raw {
            s.push_str("-raw");
        }
        s.push_str(".png");
        s
    }
}

/// The mode a filter key selects.
fn mode_of(key: Key) -> Option<Mode> {
    Some(match key {
        Key::Digit(d @ 1..=8) => Mode::Filter(Filter::from_lab_mode(d).ok()?),
        Key::Digit(9) => Mode::Filter(Filter::Ewa),
        Key::Digit(0) => Mode::Reference,
        Key::Letter('e') => Mode::Filter(Filter::EwaProbes),
        Key::Letter('b') => Mode::Filter(Filter::Bicubic),
        Key::Letter('m') => Mode::Filter(Filter::Ripmap),
        Key::Letter('t') => Mode::Filter(Filter::Sat),
        _ => return None,
    })
}

/// Parse a `--keys` script: comma-separated key names, each optionally prefixed `shift+`:
/// `0`-`9`, `a`-`z`, `tab`, `esc`, `f12`, `[`, `]`, `left`, `right`, `up`, `down`, `pageup`,
/// `pagedown`. Upper-case letters mean Shift (`V` = `shift+v`).
///
/// # Errors
/// The first token that is not a key, with the list of names.
pub fn parse_keys(script: &str) -> Result<Vec<Press>, String> {
    let mut out = Vec::new();
    for token in script.split(',').map(str::trim).filter(|t| !t.is_empty()) {
        let (mut shift, name) = match token.get(..6) {
            Some(p) if p.eq_ignore_ascii_case("shift+") => (true, &token[6..]),
            _ => (false, token),
        };
        let key = match name.to_ascii_lowercase().as_str() {
            "tab" => Key::Tab,
            "esc" | "escape" => Key::Escape,
            "f12" => Key::F12,
            "[" => Key::BracketLeft,
            "]" => Key::BracketRight,
            "left" => Key::Left,
            "right" => Key::Right,
            "up" => Key::Up,
            "down" => Key::Down,
            "pageup" => Key::PageUp,
            "pagedown" => Key::PageDown,
            _ => {
                let mut chars = name.chars();
                match (chars.next(), chars.next()) {
                    (Some(c @ '0'..='9'), None) => Key::Digit(c as u8 - b'0'),
                    (Some(c), None) if c.is_ascii_alphabetic() => {
                        shift |= c.is_ascii_uppercase();
                        Key::Letter(c.to_ascii_lowercase())
                    }
                    _ => {
                        return Err(format!(
                            "{token:?} is not a key; use 0-9, a-z, tab, esc, f12, [, ], left, right, up, \
                             down, pageup, pagedown, each optionally as shift+KEY"
                        ))
                    }
                }
            }
        };
        out.push(Press { key, shift });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(key: Key) -> Press {
        Press { key, shift: false }
    }

    fn shift(key: Key) -> Press {
        Press { key, shift: true }
    }

    #[test]
    fn digits_are_the_lab_modes_and_the_other_filter_keys() {
        let mut s = ViewState::new(Mode::Filter(Filter::Nearest), texel::ColorHandling::Srgb);
        for d in 1..=8u8 {
            assert_eq!(s.apply(press(Key::Digit(d))), Effect::None);
            assert_eq!(s.left, Mode::Filter(Filter::from_lab_mode(d).unwrap()));
            assert_eq!(Filter::from_lab_mode(d).unwrap().lab_mode(), Some(d));
        }
        let cases = [
            (Key::Digit(9), Mode::Filter(Filter::Ewa)),
            (Key::Digit(0), Mode::Reference),
            (Key::Letter('e'), Mode::Filter(Filter::EwaProbes)),
            (Key::Letter('b'), Mode::Filter(Filter::Bicubic)),
            (Key::Letter('m'), Mode::Filter(Filter::Ripmap)),
            (Key::Letter('t'), Mode::Filter(Filter::Sat)),
        ];
        for (k, m) in cases {
            s.apply(press(k));
            assert_eq!(s.left, m);
        }
        assert!(!s.split);
    }

    #[test]
    fn shift_sets_the_right_half_and_tab_toggles_the_split() {
        let mut s = ViewState::new(Mode::Filter(Filter::Trilinear), texel::ColorHandling::Srgb);
        s.apply(shift(Key::Digit(8)));
        assert!(s.split);
        assert_eq!(s.left, Mode::Filter(Filter::Trilinear));
        assert_eq!(s.right, Mode::Filter(Filter::Aniso16));
        assert_eq!(s.modes().len(), 2);
        s.apply(press(Key::Tab));
        assert!(!s.split);
        assert_eq!(s.modes(), vec![Mode::Filter(Filter::Trilinear)]);
        s.apply(press(Key::Tab));
        assert_eq!(s.modes()[1], Mode::Filter(Filter::Aniso16));
    }

    #[test]
    fn v_cycles_every_view_both_ways() {
        let mut s = ViewState::new(Mode::Reference, texel::ColorHandling::Srgb);
        let mut seen = vec![s.view];
        for _ in 0..View::ALL.len() - 1 {
            s.apply(press(Key::Letter('v')));
            seen.push(s.view);
        }
        assert_eq!(seen, View::ALL.to_vec());
        s.apply(press(Key::Letter('v')));
        assert_eq!(s.view, View::Color);
        s.apply(shift(Key::Letter('v')));
        assert_eq!(s.view, View::Barycentric);
    }

    #[test]
    fn toggles_bias_and_effects() {
        let mut s = ViewState::new(Mode::Reference, texel::ColorHandling::Srgb);
        s.apply(press(Key::Letter('p')));
        assert_eq!(s.perspective, Perspective::Affine);
        s.apply(press(Key::Letter('p')));
        assert_eq!(s.perspective, Perspective::Correct);
        s.apply(press(Key::Letter('q')));
        assert_eq!(s.derivatives, Derivatives::Quad);
        s.apply(press(Key::Letter('c')));
        assert_eq!(s.color, texel::ColorHandling::Raw);
        s.apply(press(Key::Letter('h')));
        assert!(s.help);
        s.apply(press(Key::BracketRight));
        s.apply(press(Key::BracketRight));
        s.apply(press(Key::BracketLeft));
        assert_eq!(s.lod_bias, 0.5);
        for _ in 0..100 {
            s.apply(press(Key::BracketLeft));
        }
        assert_eq!(s.lod_bias, -MAX_BIAS);
        assert_eq!(s.apply(press(Key::F12)), Effect::Screenshot);
        assert_eq!(s.apply(press(Key::Escape)), Effect::Quit);
        assert_eq!(s.apply(press(Key::Letter('r'))), Effect::ResetCamera);
        for k in [Key::Letter('w'), Key::Left, Key::PageDown] {
            assert_eq!(s.apply(press(k)), Effect::Move);
        }
        assert_eq!(s.file_name(), "texel-reference-color-quad-bias-8.0-raw.png");
    }

    #[test]
    fn scripts_parse_to_presses() {
        let keys = parse_keys("1, 5,v,tab,shift+3,V,[,],f12,Esc,pagedown").unwrap();
        assert_eq!(
            keys,
            vec![
                press(Key::Digit(1)),
                press(Key::Digit(5)),
                press(Key::Letter('v')),
                press(Key::Tab),
                shift(Key::Digit(3)),
                shift(Key::Letter('v')),
                press(Key::BracketLeft),
                press(Key::BracketRight),
                press(Key::F12),
                press(Key::Escape),
                press(Key::PageDown),
            ]
        );
        assert!(parse_keys("").unwrap().is_empty());
        let err = parse_keys("1,ctrl+x").unwrap_err();
        assert!(err.contains("\"ctrl+x\" is not a key"), "{err}");
        assert!(parse_keys("12").is_err());
    }

    #[test]
    fn the_help_table_names_every_key_the_state_handles() {
        let table = key_table();
        for name in [
            "1-8", "9 / 0", "E B M T", "Shift", "Tab", "V", "P", "Q", "[ ]", "C", "H", "F12",
            "Esc", "WASD", "R",
        ] {
            assert!(table.contains(name), "{name} missing from\n{table}");
        }
        // Every letter the state reacts to appears in the table.
        for c in 'a'..='z' {
            let mut s = ViewState::new(Mode::Reference, texel::ColorHandling::Srgb);
            let before = s.clone();
            let effect = s.apply(press(Key::Letter(c)));
            if effect != Effect::None || s != before {
                let upper = c.to_ascii_uppercase().to_string();
                assert!(
                    KEYS.iter().any(|k| k
                        .keys
                        .split([' ', ',', '/'])
                        .any(|w| w == upper || (w == "WASD" && "wasd".contains(c)))),
                    "{c} does something but is not in the table"
                );
            }
        }
    }
}
