//! Progress bars on a terminal (indicatif); nothing when stderr is not a terminal.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use texel::compare::Stage;
use texel::raster::ReferenceStatus;

/// A bar counting `total` units of `what`, drawn on stderr only if it is a terminal.
pub(crate) fn bar(total: u64, what: &str) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// Show a reference's round on `pb`.
pub(crate) fn show_status(pb: &indicatif::ProgressBar, s: &ReferenceStatus) {
    pb.set_length(s.total.max(1));
    pb.set_position(s.done);
    pb.set_message(format!(
        "round {} ({} pixels to {} spp, {:.1} % converged)",
        s.round,
        s.active,
        s.spp,
        100.0 * s.converged
    ));
}

/// Progress bars for a comparison: its own (a bar for each reference's rounds, then one over the
/// filters) or, where a caller shows one bar over several comparisons (`texel demo`), that bar,
/// counting the reference and each filter.
pub(crate) struct Bars {
    shared: Option<(indicatif::ProgressBar, String)>,
    filters: usize,
    /// The bar drawn now, of the comparison's own.
    own: std::sync::Mutex<Option<indicatif::ProgressBar>>,
}

impl Bars {
    /// The comparison's own bars, over `filters` filters.
    pub(crate) fn own(filters: usize) -> Self {
        Bars {
            shared: None,
            filters,
            own: std::sync::Mutex::new(None),
        }
    }

    /// `shared`, its messages prefixed by the scene's `label`.
    pub(crate) fn shared(shared: indicatif::ProgressBar, label: &str) -> Self {
        Bars {
            shared: Some((shared, label.to_string())),
            filters: 0,
            own: std::sync::Mutex::new(None),
        }
    }

    /// Clear the bar the comparison drew last.
    pub(crate) fn finish(&self) {
        if let Some(pb) = self.bar().take() {
            pb.finish_and_clear();
        }
    }

    fn bar(&self) -> std::sync::MutexGuard<'_, Option<indicatif::ProgressBar>> {
        self.own.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The own bar, made as `make` says unless one is drawn.
    fn own_bar(&self, make: impl FnOnce() -> indicatif::ProgressBar) -> indicatif::ProgressBar {
        self.bar().get_or_insert_with(make).clone()
    }
}

impl texel::compare::Progress for Bars {
    fn stage(&self, stage: Stage<'_>) {
        match (stage, &self.shared) {
            (Stage::Reference { n, of }, None) => {
                if n > 0 {
                    texel_io::stderr_line(format_args!("orbit frame {n} of {}", of - 1));
                }
                self.finish();
                *self.bar() = Some(bar(1, "reference"));
            }
            (Stage::Reference { .. }, Some((pb, label))) => {
                pb.set_message(format!("{label}: reference"));
            }
            (Stage::Filter(name), None) => self
                .own_bar(|| bar(self.filters as u64, "filters"))
                .set_message(name.to_string()),
            (Stage::Filter(name), Some((pb, label))) => pb.set_message(format!("{label}: {name}")),
        }
    }

    fn reference(&self, s: &ReferenceStatus) {
        if self.shared.is_none() {
            if let Some(pb) = self.bar().as_ref() {
                show_status(pb, s);
            }
        }
    }

    fn done(&self, stage: Stage<'_>) {
        match (stage, &self.shared) {
            (Stage::Reference { n: 0, .. }, Some((pb, _))) => pb.inc(1),
            (Stage::Reference { .. }, None) => self.finish(),
            (Stage::Reference { .. }, Some(_)) => {}
            (Stage::Filter(_), Some((pb, _))) => pb.inc(1),
            (Stage::Filter(_), None) => {
                if let Some(pb) = self.bar().as_ref() {
                    pb.inc(1);
                }
            }
        }
    }
}
