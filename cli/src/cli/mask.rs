//! `--mask FILE` and `--mask-falloff RINGS` of `fair` and `multires`: read a vertex list (0-based
//! indices in the input file's own vertex order, [`fairmesh::io::read_vertex_list`]) and turn it
//! into a [`Mask`] on the loaded, welded mesh ([`fairmesh::fairing::mask`]).

use anyhow::Context;
use clap::Args;
use fairmesh::fairing::mask::Mask;
use fairmesh::io::{loaded_vertices, read_vertex_list, Source};
use fairmesh::{Topology, TriMesh};
use std::path::PathBuf;

#[derive(Args, Debug, Clone, Default)]
pub struct MaskArgs {
    /// Fair only these vertices: a text file of 0-based vertex indices in the input file's
    /// vertex order, one a line (blank lines and `#` comments allowed). Every other vertex keeps
    /// its position exactly.
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// With --mask: fade the fairing out over this many rings of vertices inside the mask's
    /// edge, so that no step shows where the faired region meets the rest.
    #[arg(long, value_name = "RINGS", default_value_t = 0, requires = "mask")]
    pub mask_falloff: usize,
}

impl MaskArgs {
    /// The mask on `mesh` (loaded from `source`), or `None` without --mask. `topology` is
    /// `mesh`'s, needed only for a falloff (built when not given).
    pub fn load(
        &self,
        source: &Source,
        mesh: &TriMesh,
        topology: Option<&Topology>,
    ) -> anyhow::Result<Option<Mask>> {
        let Some(path) = &self.mask else {
            return Ok(None);
        };
        let list = read_vertex_list(path)?;
        let vertices = loaded_vertices(source, &list, path)?;
        let mask = Mask::from_vertices(mesh.positions.len(), vertices);
        anyhow::ensure!(
            mask.painted_count() > 0,
            "{}: the vertex list names no vertex of the mesh, so nothing would be faired",
            path.display()
        );
        if self.mask_falloff == 0 {
            return Ok(Some(mask));
        }
        let built;
        let topology = match topology {
            Some(topology) => topology,
            None => {
                built = Topology::build(mesh);
                &built
            }
        };
        Ok(Some(mask.with_falloff(topology, self.mask_falloff)))
    }
}

/// A sentence part for the CLI's report: how many vertices the mask let move.
pub fn describe(mask: Option<&Mask>) -> String {
    mask.map(|m| format!("{} of {} vertices masked in; ", m.painted_count(), m.len()))
        .unwrap_or_default()
}

/// Loads the mask of `args` or says which file was at fault.
pub fn load_for(
    args: &MaskArgs,
    source: &Source,
    mesh: &TriMesh,
    topology: Option<&Topology>,
) -> anyhow::Result<Option<Mask>> {
    args.load(source, mesh, topology)
        .context("reading the mask (--mask)")
}
