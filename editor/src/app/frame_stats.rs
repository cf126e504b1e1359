//! CPU time the UI thread spends per frame, for the Performance section and `--log-frames`.

use std::collections::VecDeque;
use std::time::Duration;
use web_time::Instant;

/// CPU time the UI thread spent per frame, for the performance readout.
#[derive(Default)]
pub struct FrameStats {
    recent: VecDeque<Duration>,
    /// Longest frame while a background job was running.
    pub max_while_busy: Duration,
    /// That frame split into applying results, uploading to the GPU, and drawing widgets.
    pub max_while_busy_parts: [Duration; 3],
    pub frames: u64,
    /// Frames over this are printed to standard error (`AppOptions::log_frames_over`).
    pub(super) log_over: Option<Duration>,
    /// The main viewport's image counts at the last frame (to tell whether it drew an image,
    /// or showed a held mesh's kept one, since).
    pub(super) images_seen: crate::render::ImageCounts,
    /// When the previous frame began (for the wait of input, see [`FrameStats::record_start`]).
    previous_start: Option<Instant>,
    /// When the first frame began (the log says when each late frame came).
    first_start: Option<Instant>,
}

impl FrameStats {
    const WINDOW: usize = 240;

    /// Records one frame: its CPU time in `App::ui`, that split into applying results, uploading
    /// and widgets, and the CPU time of the viewport's last offscreen draw (recorded in the
    /// previous frame's paint callback, which runs after `App::ui` returns).
    pub(super) fn record(
        &mut self,
        elapsed: Duration,
        parts: [Duration; 3],
        render: Duration,
        busy: bool,
    ) {
        if let Some(limit) = self.log_over {
            if elapsed > limit || render > limit {
                let ms = |d: Duration| d.as_secs_f64() * 1e3;
                eprintln!(
                    "frame {}: {:.1} ms UI CPU (results {:.1}, upload {:.1}, widgets {:.1}), \
                     previous viewport draw {:.1} ms{}",
                    self.frames,
                    ms(elapsed),
                    ms(parts[0]),
                    ms(parts[1]),
                    ms(parts[2]),
                    ms(render),
                    if busy { ", working" } else { "" }
                );
            }
        }
        if self.recent.len() == Self::WINDOW {
            self.recent.pop_front();
        }
        self.recent.push_back(elapsed);
        if busy && elapsed > self.max_while_busy {
            self.max_while_busy = elapsed;
            self.max_while_busy_parts = parts;
        }
        self.frames += 1;
    }

    /// Notes the start of a frame. With logging on, a frame that takes input events more than
    /// `max(limit, 50 ms)` after the previous frame began is printed: while input arrives
    /// continuously (a pointer being moved), that gap is how long the input waited for an answer,
    /// whatever held the window (the UI thread, the GPU, the window system). After a quiet
    /// spell the gap only says the window was idle.
    pub(super) fn record_start(&mut self, started: Instant, had_input: bool) {
        let previous = self.previous_start.replace(started);
        let first = *self.first_start.get_or_insert(started);
        let (Some(limit), Some(previous)) = (self.log_over, previous) else {
            return;
        };
        let gap = started.saturating_duration_since(previous);
        if had_input && gap > limit.max(Duration::from_millis(50)) {
            eprintln!(
                "frame {} at {:.2} s: input waited up to {:.1} ms (since the previous frame began)",
                self.frames,
                started.saturating_duration_since(first).as_secs_f64(),
                gap.as_secs_f64() * 1e3
            );
        }
    }

    /// With logging on, prints when a background job's result arrived (to tell which long frames
    /// followed which result).
    pub(super) fn log_arrival(&self, what: &str) {
        if let (Some(_), Some(first)) = (self.log_over, self.first_start) {
            eprintln!("at {:.2} s: {what} arrived", first.elapsed().as_secs_f64());
        }
    }

    /// Frame statistics that print frames over `limit` to standard error.
    pub(super) fn logging_over(limit: Option<Duration>) -> Self {
        Self {
            log_over: limit,
            ..Self::default()
        }
    }

    pub fn last(&self) -> Duration {
        self.recent.back().copied().unwrap_or_default()
    }
    pub fn mean(&self) -> Duration {
        if self.recent.is_empty() {
            return Duration::ZERO;
        }
        self.recent.iter().sum::<Duration>() / self.recent.len() as u32
    }
    pub fn max(&self) -> Duration {
        self.recent.iter().max().copied().unwrap_or_default()
    }
    pub fn reset_busy_max(&mut self) {
        self.max_while_busy = Duration::ZERO;
        self.max_while_busy_parts = [Duration::ZERO; 3];
    }
}
