//! The editor's background tasks, one file per kind, each holding its launch (a job on a worker)
//! and the handling of its result on the UI thread.

pub mod document;
pub mod export;
pub mod fairing;
pub mod hierarchy;
pub mod load;
pub mod mask;
pub mod measure;
pub mod view_image;
