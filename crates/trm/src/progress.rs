//! Progress of long commands: an `indicatif` bar with rate and ETA when stderr is a terminal,
//! plain lines every few seconds (and at the end) otherwise, so logs stay readable.

use std::io::IsTerminal as _;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// Seconds between plain lines when stderr is not a terminal.
const PLAIN_EVERY: f64 = 5.0;

/// One command's progress towards `len` steps.
pub struct Progress {
    bar: Option<ProgressBar>,
    label: String,
    len: u64,
    started: Instant,
    last_line: f64,
    /// Whether the plain line for the last step was printed.
    ended: bool,
}

impl Progress {
    /// Progress of `len` steps named `label` (e.g. "points", "runs").
    pub fn new(label: &str, len: u64) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(len);
            let style = ProgressStyle::with_template(
                "{bar:30} {pos}/{len} {prefix} ({elapsed}, ETA {eta}) {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_prefix(label.to_string());
            bar
        });
        Progress {
            bar,
            label: label.to_string(),
            len,
            started: Instant::now(),
            last_line: f64::NEG_INFINITY,
            ended: false,
        }
    }

    /// `pos` of `len` steps done; `detail` is shown after the bar (or in the plain line).
    pub fn set(&mut self, pos: u64, len: u64, detail: &str) {
        self.len = len;
        if let Some(bar) = &self.bar {
            bar.set_length(len);
            bar.set_position(pos);
            bar.set_message(detail.to_string());
            return;
        }
        let seconds = self.started.elapsed().as_secs_f64();
        let last = pos >= self.len;
        if (seconds - self.last_line >= PLAIN_EVERY || last) && !(last && self.ended) {
            self.ended = last;
            let eta = if pos > 0 {
                format!(
                    ", ETA {:.0} s",
                    seconds / pos as f64 * self.len.saturating_sub(pos) as f64
                )
            } else {
                String::new()
            };
            eprintln!(
                "{pos}/{} {}, {seconds:.1} s{eta}{}{detail}",
                self.len,
                self.label,
                if detail.is_empty() { "" } else { "; " }
            );
            self.last_line = seconds;
        }
    }

    /// Clears the bar (the plain lines stay).
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
