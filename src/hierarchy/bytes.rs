//! A hierarchy as bytes and back ([`Hierarchy::to_bytes`], [`Hierarchy::from_bytes`]): for
//! handing a built hierarchy to another copy of the same program (another process, or a second
//! instance of the library in the same program) without building it again. It is not a file
//! format: the bytes are read back only by the same version of the library.

use super::{Hierarchy, NEVER, NEXT_HIERARCHY_ID};
use crate::fairing::creases::FeatureClass;
use crate::mesh::TriMesh;
use std::sync::atomic::Ordering;

/// The first bytes of a hierarchy's byte form, with its layout's version.
const MAGIC: &[u8; 8] = b"FMHIER01";

/// What is wrong with bytes given to [`Hierarchy::from_bytes`].
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("not a hierarchy's bytes: {0}")]
pub struct HierarchyBytesError(String);

fn put_u32s(out: &mut Vec<u8>, values: impl ExactSizeIterator<Item = u32>) {
    out.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for value in values {
        out.extend_from_slice(&value.to_le_bytes());
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn take(&mut self, count: usize, what: &str) -> Result<&[u8], HierarchyBytesError> {
        if self.bytes.len() < count {
            return Err(HierarchyBytesError(format!("{what}: the bytes end early")));
        }
        let (head, tail) = self.bytes.split_at(count);
        self.bytes = tail;
        Ok(head)
    }

    /// A list of words (its word count first), `width` words per item.
    fn words(&mut self, width: usize, what: &str) -> Result<Vec<u32>, HierarchyBytesError> {
        let count = u64::from_le_bytes(self.take(8, what)?.try_into().unwrap_or_default());
        let words = usize::try_from(count)
            .ok()
            .filter(|&n| n.checked_mul(4).is_some_and(|b| b <= self.bytes.len()))
            .ok_or_else(|| HierarchyBytesError(format!("{what}: the bytes end early")))?;
        if !words.is_multiple_of(width) {
            return Err(HierarchyBytesError(format!(
                "{what}: {words} numbers do not make items of {width}"
            )));
        }
        let raw = self.take(words * 4, what)?;
        Ok(raw
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect())
    }
}

fn triples(words: Vec<u32>) -> Vec<[u32; 3]> {
    words.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}

fn points(words: Vec<u32>) -> Vec<[f32; 3]> {
    words
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]].map(f32::from_bits))
        .collect()
}

/// Checks that every id in `ids` is below `limit` (or is `allowed`).
fn check_ids(
    ids: impl IntoIterator<Item = u32>,
    limit: usize,
    allowed: Option<u32>,
    what: &str,
) -> Result<(), HierarchyBytesError> {
    match ids
        .into_iter()
        .find(|&id| id as usize >= limit && Some(id) != allowed)
    {
        Some(id) => Err(HierarchyBytesError(format!(
            "{what}: id {id} is out of range (there are {limit})"
        ))),
        None => Ok(()),
    }
}

impl Hierarchy {
    /// The hierarchy as bytes, read back by [`Hierarchy::from_bytes`] (a few bytes over the
    /// size of its arrays).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.record_bytes() + 64);
        out.extend_from_slice(MAGIC);
        let flat3 = |v: &[[u32; 3]]| v.iter().flatten().copied().collect::<Vec<_>>();
        let bits3 = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        for list in [
            bits3(&self.base.positions),
            flat3(&self.base.triangles),
            self.order.clone(),
            self.rank.clone(),
            bits3(&self.positions),
            flat3(&self.triangles),
            self.face_order.clone(),
            self.target.clone(),
            self.six_split_volume.iter().map(|x| x.to_bits()).collect(),
            self.level_vertices.clone(),
            self.level_faces.clone(),
            self.feature_class
                .iter()
                .map(|class| match class {
                    FeatureClass::Smooth => 0,
                    FeatureClass::Crease => 1,
                    FeatureClass::Corner => 2,
                })
                .collect(),
            self.crease_edges.iter().flatten().copied().collect(),
            self.non_manifold.clone(),
            self.loose.clone(),
        ] {
            put_u32s(&mut out, list.into_iter());
        }
        let ms: Vec<u8> = self.level_ms.iter().flat_map(|x| x.to_le_bytes()).collect();
        out.extend_from_slice(&(self.level_ms.len() as u64).to_le_bytes());
        out.extend_from_slice(&ms);
        out
    }

    /// A hierarchy from the bytes [`Hierarchy::to_bytes`] made: equal to the one written, with
    /// an identity of its own (workspaces set up for the original set the levels up again).
    ///
    /// # Errors
    /// Bytes that are not a hierarchy's (another layout, cut short, ids out of range).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, HierarchyBytesError> {
        let mut reader = Reader { bytes };
        if reader.take(MAGIC.len(), "the header")? != MAGIC {
            return Err(HierarchyBytesError(
                "the header is not this version's".into(),
            ));
        }
        let base_positions = points(reader.words(3, "the base positions")?);
        let base_triangles = triples(reader.words(3, "the base triangles")?);
        let order = reader.words(1, "the order")?;
        let rank = reader.words(1, "the ranks")?;
        let positions = points(reader.words(3, "the positions")?);
        let triangles = triples(reader.words(3, "the triangles")?);
        let face_order = reader.words(1, "the face order")?;
        let target = reader.words(1, "the collapse targets")?;
        let six_split_volume = reader
            .words(1, "the volumes")?
            .into_iter()
            .map(f32::from_bits)
            .collect();
        let level_vertices = reader.words(1, "the level sizes")?;
        let level_faces = reader.words(1, "the level face counts")?;
        let feature_class = reader
            .words(1, "the crease classes")?
            .into_iter()
            .map(|class| match class {
                0 => Ok(FeatureClass::Smooth),
                1 => Ok(FeatureClass::Crease),
                2 => Ok(FeatureClass::Corner),
                _ => Err(HierarchyBytesError(format!(
                    "crease class {class} is unknown"
                ))),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let crease_edges = reader
            .words(2, "the crease edges")?
            .chunks_exact(2)
            .map(|e| [e[0], e[1]])
            .collect::<Vec<_>>();
        let non_manifold = reader.words(1, "the non-manifold vertices")?;
        let loose = reader.words(1, "the loose faces")?;
        let ms_count = u64::from_le_bytes(
            reader
                .take(8, "the level times")?
                .try_into()
                .unwrap_or_default(),
        );
        let ms_bytes = usize::try_from(ms_count)
            .ok()
            .and_then(|n| n.checked_mul(8))
            .ok_or_else(|| HierarchyBytesError("the level times: the bytes end early".into()))?;
        let level_ms = reader
            .take(ms_bytes, "the level times")?
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
            .collect::<Vec<_>>();
        if !reader.bytes.is_empty() {
            return Err(HierarchyBytesError("bytes follow the end".into()));
        }

        let vertices = positions.len();
        // Every face of M0, those left out of the levels included.
        let faces = base_triangles.len();
        let six_split_volume: Vec<f32> = six_split_volume;
        let same = [
            order.len(),
            rank.len(),
            target.len(),
            six_split_volume.len(),
        ];
        if base_positions.len() != vertices
            || triangles.len() > faces
            || face_order.len() != faces
            || same.iter().any(|&n| n != vertices)
            || level_vertices.len() != level_faces.len()
            || !(feature_class.is_empty() || feature_class.len() == vertices)
        {
            return Err(HierarchyBytesError("the list lengths do not agree".into()));
        }
        check_ids(order.iter().copied(), vertices, None, "the order")?;
        check_ids(rank.iter().copied(), vertices, None, "the ranks")?;
        check_ids(
            target.iter().copied(),
            vertices,
            Some(NEVER),
            "the collapse targets",
        )?;
        check_ids(
            triangles.iter().flatten().copied(),
            vertices,
            None,
            "the triangles",
        )?;
        check_ids(
            base_triangles.iter().flatten().copied(),
            vertices,
            None,
            "the base triangles",
        )?;
        check_ids(face_order.iter().copied(), faces, None, "the face order")?;
        check_ids(
            crease_edges.iter().flatten().copied(),
            vertices,
            None,
            "the crease edges",
        )?;
        check_ids(
            non_manifold.iter().copied(),
            vertices,
            None,
            "the non-manifold vertices",
        )?;
        check_ids(loose.iter().copied(), faces, None, "the loose faces")?;
        if level_vertices.iter().any(|&n| n as usize > vertices)
            || level_faces.iter().any(|&n| n as usize > faces)
        {
            return Err(HierarchyBytesError(
                "a level is larger than the mesh".into(),
            ));
        }
        Ok(Hierarchy {
            base: TriMesh::new(base_positions, base_triangles),
            id: NEXT_HIERARCHY_ID.fetch_add(1, Ordering::Relaxed),
            order,
            rank,
            positions,
            triangles,
            face_order,
            target,
            six_split_volume,
            level_vertices,
            level_faces,
            level_ms,
            feature_class,
            crease_edges,
            non_manifold,
            loose,
        })
    }
}
