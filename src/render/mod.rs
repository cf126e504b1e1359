//! The wgpu viewport renderer (feature `gui`). STUB: to be filled by the editor work.
