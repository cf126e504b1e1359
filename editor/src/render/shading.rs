//! How the viewport lights the surface: the shading (one normal per triangle, or normals
//! blended across triangles from the vertices' own) and the lighting (a simple key light, or a
//! studio set-up of key, fill and rim lights with a soft highlight). The editor stores both in
//! its settings, so they serialise; the shading's names are the ones the editor shows (the
//! lighting is its "Studio lighting" checkbox).

use serde::{Deserialize, Serialize};

/// Which normal a pixel is lit with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Shading {
    /// One normal per triangle: every facet shows, as it is.
    Flat,
    /// Area-weighted vertex normals blended across each triangle: a fair surface looks smooth
    /// and its highlights run evenly; split at sharp edges
    /// ([`crate::render::normals::SHARP_EDGE_ANGLE`]), which stay crisp.
    #[default]
    Smooth,
}

impl Shading {
    pub const ALL: [Shading; 2] = [Shading::Flat, Shading::Smooth];

    pub fn label(self) -> &'static str {
        match self {
            Shading::Flat => "Flat",
            Shading::Smooth => "Smooth",
        }
    }
}

/// The lights the surface is lit by (they move with the camera).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Lighting {
    /// One key light above left of the viewer plus light from the eye: plain and even.
    Simple,
    /// A warm key light, a cool fill from the right, a rim light on the outline, sky and ground
    /// ambient and a soft highlight: bumps and dents show in the highlight's shape.
    #[default]
    Studio,
}
