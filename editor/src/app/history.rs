//! Undo and redo of document changes (noise, applying a result, loading).
//!
//! The history stores whole document states, not diffs: every change the editor makes replaces the
//! positions (or the whole mesh), and states share what did not change through `Arc`, so a step
//! costs the positions it changed. The history is bounded by a byte budget: the oldest states go
//! first, but the current state and one step back always stay.

use std::collections::VecDeque;

/// Something that can say how many bytes it keeps alive, for the history's budget.
pub trait SizeInBytes {
    fn size_in_bytes(&self) -> usize;
}

/// Undo/redo stacks around a current state.
#[derive(Debug)]
pub struct History<T> {
    undo: VecDeque<(String, T)>,
    redo: Vec<(String, T)>,
    budget_bytes: usize,
}

impl<T: SizeInBytes> History<T> {
    pub fn new(budget_bytes: usize) -> Self {
        Self {
            undo: VecDeque::new(),
            redo: Vec::new(),
            budget_bytes,
        }
    }

    /// Records `previous` (the state before a change named `label`) and forgets the redo stack.
    pub fn record(&mut self, label: impl Into<String>, previous: T) {
        self.redo.clear();
        self.undo.push_back((label.into(), previous));
        self.trim();
    }

    /// Goes one step back: gives the state to restore, and keeps `current` for redo.
    pub fn undo(&mut self, current: T) -> Result<T, T> {
        match self.undo.pop_back() {
            Some((label, previous)) => {
                self.redo.push((label, current));
                Ok(previous)
            }
            None => Err(current),
        }
    }

    /// Goes one step forward again.
    pub fn redo(&mut self, current: T) -> Result<T, T> {
        match self.redo.pop() {
            Some((label, next)) => {
                self.undo.push_back((label, current));
                Ok(next)
            }
            None => Err(current),
        }
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Label of the change that undo would revert.
    pub fn undo_label(&self) -> Option<&str> {
        self.undo.back().map(|(l, _)| l.as_str())
    }

    /// Label of the change that redo would repeat.
    pub fn redo_label(&self) -> Option<&str> {
        self.redo.last().map(|(l, _)| l.as_str())
    }

    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }

    fn trim(&mut self) {
        let mut total: usize = self
            .undo
            .iter()
            .chain(self.redo.iter())
            .map(|(_, s)| s.size_in_bytes())
            .sum();
        while total > self.budget_bytes && self.undo.len() > 1 {
            if let Some((_, dropped)) = self.undo.pop_front() {
                total -= dropped.size_in_bytes();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl SizeInBytes for Vec<u8> {
        fn size_in_bytes(&self) -> usize {
            self.len()
        }
    }

    #[test]
    fn undo_and_redo_walk_the_states_in_order() {
        let mut history = History::new(1 << 20);
        let mut current = vec![0u8];
        for step in 1..=3u8 {
            history.record(
                format!("step {step}"),
                std::mem::replace(&mut current, vec![step]),
            );
        }
        assert_eq!(history.undo_label(), Some("step 3"));
        current = history.undo(current).unwrap();
        assert_eq!(current, vec![2]);
        current = history.undo(current).unwrap();
        assert_eq!(current, vec![1]);
        assert_eq!(history.redo_label(), Some("step 2"));
        current = history.redo(current).unwrap();
        assert_eq!(current, vec![2]);
        // A new change forgets what could have been redone.
        history.record("other", std::mem::replace(&mut current, vec![9]));
        assert!(!history.can_redo());
        current = history.undo(current).unwrap();
        assert_eq!(current, vec![2]);
        current = history.undo(current).unwrap();
        current = history.undo(current).unwrap();
        assert_eq!(current, vec![0]);
        assert!(history.undo(current.clone()).is_err());
    }

    #[test]
    fn the_budget_drops_the_oldest_states_but_keeps_one_step() {
        let mut history = History::new(250);
        let mut current = vec![0u8; 100];
        for step in 1..=5u8 {
            history.record("big", std::mem::replace(&mut current, vec![step; 100]));
        }
        // Two states of 100 bytes fit in 250.
        current = history.undo(current).unwrap();
        assert_eq!(current[0], 4);
        current = history.undo(current).unwrap();
        assert_eq!(current[0], 3);
        assert!(history.undo(current).is_err());

        let mut tiny = History::new(10);
        tiny.record("huge", vec![1u8; 1000]);
        assert!(tiny.can_undo(), "one step back is always kept");
    }
}
