//! The editor (feature `gui`). STUB: to be filled by the editor work.

/// Opens the editor window on `file`, or on the bundled bunny.
pub fn run(_file: Option<std::path::PathBuf>) -> anyhow::Result<()> {
    anyhow::bail!("the editor is not implemented yet")
}
