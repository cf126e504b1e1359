//! Generation numbers: latest wins. The UI bumps a [`Generation`] for each new request (a file,
//! a document change, a slider value); a job remembers the [`GenerationId`] it was started under,
//! its progress hook sees the counter move on and stops, and the UI drops a result whose
//! generation is not the current one.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A generation counter shared between the UI and the jobs: latest wins. The UI bumps it for
/// each new request (a file, a document change, a slider value); a job started under an older
/// [`GenerationId`] stops, and its result is dropped.
#[derive(Clone, Default)]
pub struct Generation(Arc<AtomicU64>);

/// One value of a [`Generation`]: what a job was started under, or what a result on screen came
/// from. A later value compares greater; the default (0) is older than any bumped one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GenerationId(u64);

impl GenerationId {
    /// The number, for keys that outlive the app's types (the renderer's mesh keys).
    pub fn get(self) -> u64 {
        self.0
    }
}

impl Generation {
    /// Starts a new generation and returns it.
    pub fn bump(&self) -> GenerationId {
        GenerationId(self.0.fetch_add(1, Ordering::SeqCst) + 1)
    }
    pub fn current(&self) -> GenerationId {
        GenerationId(self.0.load(Ordering::SeqCst))
    }
    pub fn is_current(&self, generation: GenerationId) -> bool {
        self.current() == generation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generations_mark_old_work_stale() {
        let generation = Generation::default();
        let first = generation.bump();
        assert!(generation.is_current(first));
        let second = generation.bump();
        assert!(!generation.is_current(first) && generation.is_current(second));
        // Latest wins: a later generation compares greater, and any beats the default.
        assert!(second > first && first > GenerationId::default());
    }
}
