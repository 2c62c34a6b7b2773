//! The progress bar of the long stages, on stderr when it is a terminal.

use odocal_pipeline::Progress;

/// A progress bar on stderr, shown only when stderr is a terminal.
pub struct Bar(Option<indicatif::ProgressBar>);

impl Bar {
    /// A bar when stderr is a terminal, nothing otherwise.
    pub fn for_stderr() -> Bar {
        use std::io::IsTerminal;
        Bar(std::io::stderr()
            .is_terminal()
            .then(indicatif::ProgressBar::hidden))
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: usize) {
        if let Some(b) = &self.0 {
            b.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            b.reset();
            b.set_length(total as u64);
            b.set_position(0);
            b.set_message(stage.to_string());
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("{msg:>24} [{bar:40}] {pos}/{len} ({eta})")
            {
                b.set_style(style.progress_chars("=> "));
            }
        }
    }
    fn advance(&self) {
        if let Some(b) = &self.0 {
            b.inc(1);
        }
    }
    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
