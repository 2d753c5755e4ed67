//! Every command has `--help` with an example.

use crate::util::*;

#[test]
fn every_command_has_help_with_an_example() {
    let commands = [
        "render",
        "reference",
        "compare",
        "warp",
        "mips",
        "demo",
        "bench",
        "bake-ao",
    ];
    let top = stdout(&ok(&["--help"]));
    for c in commands {
        assert!(top.contains(c), "top-level help lacks {c}: {top}");
        let help = stdout(&ok(&[c, "--help"]));
        assert!(
            help.contains(&format!("Example: texel {c} ")),
            "texel {c} --help: {help}"
        );
        assert!(help.contains("Usage: texel "), "{help}");
    }
}

/// The scene argument's help names every built-in scene.
#[test]
fn scene_help_lists_every_builtin() {
    for c in ["render", "reference", "compare", "bench"] {
        let help = stdout(&ok(&[c, "--help"]));
        for name in BUILTINS {
            assert!(
                help.contains(&format!("builtin:{name},"))
                    || help.contains(&format!("builtin:{name})")),
                "texel {c} --help lacks builtin:{name}"
            );
        }
    }
}
