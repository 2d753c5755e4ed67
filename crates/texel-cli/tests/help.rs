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
