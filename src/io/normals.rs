//! How a file's normals change when its vertices move ([`NormalTurns`], [`SmoothGroups`],
//! [`Turn`]), and the area-weighted unit vertex normals the writers give a bare mesh
//! ([`unit_vertex_normals`]). Written back into its own format, a file's normals (and glTF
//! tangents) are turned by the rotation that takes the area-weighted normal of their faces
//! before the move to the one after, so split normals stay split, smooth ones stay smooth, and a
//! file's own custom normals keep their character.

use crate::mesh::TriMesh;
use glam::{DQuat, DVec3};

/// How the normals of a file change when its vertices move. Each file normal (an OBJ `vn`, a PLY
/// vertex's nx ny nz, an element of a glTF NORMAL accessor) belongs to a slot, and each slot
/// gathers the area vectors of the faces that use it, before and after the move; the normal is
/// then turned by the shortest rotation between the two sums. Normals whose faces did not move
/// are left alone. An OBJ's slots are its `vn` lines (the file says which corners share a
/// normal). A glTF or PLY normal has a slot of its own when it is the normal of its own faces (a
/// flat-shaded triangle, a vertex nothing else shares), so flat parts stay flat per face; a normal
/// that is not (it was smoothed over faces of other file vertices: a smooth normal split at a UV
/// seam or a material boundary) shares its slot with the other normals of the same value on the
/// same welded vertex ([`SmoothGroups`]), so the copies stay equal, while normals that differ
/// there (a hard edge) stay apart.
pub(crate) struct NormalTurns {
    /// Per slot, side by side so that adding a face touches one place per corner.
    slots: Vec<SlotSums>,
}

/// The area sums of one slot's faces, before and after the move, and whether any of them moved.
#[derive(Clone, Copy, Default)]
pub(crate) struct SlotSums {
    before: DVec3,
    after: DVec3,
    moved: bool,
}

impl SlotSums {
    /// The sum of the area vectors of the faces before the move.
    pub(crate) fn area_before(&self) -> DVec3 {
        self.before
    }

    /// These sums added to those of an empty slot (exactly what [`NormalTurns::merge_slot`]
    /// gives a slot that has only this one normal).
    pub(crate) fn alone(self) -> SlotSums {
        let mut sums = SlotSums::default();
        sums.merge(self);
        sums
    }

    /// The sums of one triangle with corners `before` and `after` the move.
    #[inline]
    pub(crate) fn of_triangle(before: [DVec3; 3], after: [DVec3; 3]) -> SlotSums {
        SlotSums {
            before: (before[1] - before[0]).cross(before[2] - before[0]),
            after: (after[1] - after[0]).cross(after[2] - after[0]),
            moved: before != after,
        }
    }

    #[inline]
    pub(crate) fn merge(&mut self, add: SlotSums) {
        self.before += add.before;
        self.after += add.after;
        self.moved |= add.moved;
    }

    /// The rotation for the normals of this slot, or `None` when they stay as they are.
    pub(crate) fn turn(&self) -> Option<Turn> {
        if !self.moved {
            return None;
        }
        let after = self.after.normalize_or_zero();
        if after == DVec3::ZERO {
            return None;
        }
        let before = self.before.normalize_or_zero();
        Some(if before == DVec3::ZERO {
            Turn::Replace(after)
        } else {
            Turn::Rotate(DQuat::from_rotation_arc(before, after))
        })
    }
}

impl NormalTurns {
    pub(crate) fn new(normals: usize) -> NormalTurns {
        NormalTurns {
            slots: vec![SlotSums::default(); normals],
        }
    }

    fn slot_mut(&mut self, n: usize) -> &mut SlotSums {
        if n >= self.slots.len() {
            self.slots.resize(n + 1, SlotSums::default());
        }
        &mut self.slots[n]
    }

    /// Add a triangle whose corners use the slots `slots`, with its corners' positions before
    /// and after.
    #[inline]
    pub(crate) fn add(&mut self, slots: [usize; 3], before: [DVec3; 3], after: [DVec3; 3]) {
        let add = SlotSums::of_triangle(before, after);
        for n in slots {
            self.slot_mut(n).merge(add);
        }
    }

    /// The sum of the area vectors of slot `n`'s faces before the move.
    pub(crate) fn area_before(&self, n: usize) -> DVec3 {
        self.slots.get(n).map_or(DVec3::ZERO, |sums| sums.before)
    }

    /// Add the sums of `from`'s slot `n` to this one's slot `slot`.
    pub(crate) fn merge_slot(&mut self, slot: usize, from: &NormalTurns, n: usize) {
        let add = from.slots.get(n).copied().unwrap_or_default();
        self.merge_sums(slot, add);
    }

    /// Add `add` to slot `slot`'s sums.
    pub(crate) fn merge_sums(&mut self, slot: usize, add: SlotSums) {
        self.slot_mut(slot).merge(add);
    }

    /// The rotation for normal `n`, or `None` when it stays as it is.
    pub(crate) fn turn(&self, n: usize) -> Option<Turn> {
        self.slots.get(n)?.turn()
    }
}

/// Slots for normals that turn together: one per (welded vertex, normal value); a normal on no
/// welded vertex gets a slot of its own.
#[derive(Default)]
pub(crate) struct SmoothGroups {
    /// Per welded vertex, the slot of the first normal value seen there (most vertices have one):
    /// looked up by index, with no hashing.
    first: Vec<Option<(usize, [u32; 3])>>,
    /// The slots of the further values on a vertex (hard edges).
    others: std::collections::HashMap<
        (usize, [u32; 3]),
        usize,
        std::hash::BuildHasherDefault<crate::mesh::PositionHasher>,
    >,
    next: usize,
}

impl SmoothGroups {
    /// The slot of a file normal whose own faces (those of its file vertex) add up to the area
    /// vector `own`, on welded vertex `welded`.
    pub(crate) fn slot_for(
        &mut self,
        own: DVec3,
        welded: Option<usize>,
        normal: [f32; 3],
    ) -> usize {
        if is_own_normal(own, normal) {
            return self.fresh();
        }
        self.slot(welded, normal)
    }

    pub(crate) fn slot(&mut self, welded: Option<usize>, normal: [f32; 3]) -> usize {
        let Some(w) = welded else {
            return self.fresh();
        };
        let bits = normal.map(f32::to_bits);
        if w >= self.first.len() {
            self.first.resize(w + 1, None);
        }
        match self.first[w] {
            Some((slot, first_bits)) if first_bits == bits => slot,
            Some(_) => match self.others.get(&(w, bits)) {
                Some(&slot) => slot,
                None => {
                    let slot = self.fresh();
                    self.others.insert((w, bits), slot);
                    slot
                }
            },
            None => {
                let slot = self.fresh();
                self.first[w] = Some((slot, bits));
                slot
            }
        }
    }

    pub(crate) fn fresh(&mut self) -> usize {
        self.next += 1;
        self.next - 1
    }
}

/// Whether a file normal is the normal of its own faces (whose area vectors add up to `own`):
/// then it gets a slot of its own ([`SmoothGroups::slot_for`]).
#[inline]
pub(crate) fn is_own_normal(own: DVec3, normal: [f32; 3]) -> bool {
    let own = own.normalize_or_zero();
    let n = dvec(normal).normalize_or_zero();
    own != DVec3::ZERO && own.dot(n) > 0.99999
}

/// What happens to one file normal.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Turn {
    /// Turned by the rotation of its faces.
    Rotate(DQuat),
    /// Its faces had no area before: it becomes their normal after.
    Replace(DVec3),
}

impl Turn {
    /// The turned normal (unit length when `normal` was), never NaN.
    pub(crate) fn normal(self, normal: [f32; 3]) -> [f32; 3] {
        let turned = match self {
            Turn::Rotate(q) => q * DVec3::from_array(normal.map(f64::from)),
            Turn::Replace(n) => n,
        };
        if turned.is_finite() {
            turned.as_vec3().to_array()
        } else {
            normal
        }
    }

    /// A direction that moves with the surface (a tangent), turned; its length is kept.
    pub(crate) fn direction(self, direction: [f32; 3]) -> [f32; 3] {
        match self {
            Turn::Rotate(q) => {
                let turned = q * DVec3::from_array(direction.map(f64::from));
                if turned.is_finite() {
                    turned.as_vec3().to_array()
                } else {
                    direction
                }
            }
            Turn::Replace(_) => direction,
        }
    }
}

/// A point in f64.
#[inline]
pub(crate) fn dvec(p: [f32; 3]) -> DVec3 {
    DVec3::from_array(p.map(f64::from))
}

/// Area-weighted unit vertex normals in f32, never NaN: a vertex whose normal sums to zero takes
/// an incident face's normal, or +Z.
pub(crate) fn unit_vertex_normals(mesh: &TriMesh) -> Vec<[f32; 3]> {
    let mut sums = vec![DVec3::ZERO; mesh.positions.len()];
    let mut fallback = vec![DVec3::ZERO; mesh.positions.len()];
    for t in 0..mesh.triangles.len() {
        let n = mesh.face_normal(t);
        let unit = n.normalize_or_zero();
        for &v in &mesh.triangles[t] {
            sums[v as usize] += n;
            if fallback[v as usize] == DVec3::ZERO {
                fallback[v as usize] = unit;
            }
        }
    }
    sums.iter()
        .zip(&fallback)
        .map(|(sum, fallback)| {
            let n = sum.normalize_or_zero();
            let n = if n != DVec3::ZERO {
                n
            } else if *fallback != DVec3::ZERO {
                *fallback
            } else {
                DVec3::Z
            };
            n.as_vec3().to_array()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_turn_with_their_faces_and_unmoved_ones_stay() {
        // Two triangles: one tilts by 90 degrees about the x axis, the other stays.
        let mut turns = NormalTurns::new(3);
        let flat = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let tilted = [DVec3::ZERO, DVec3::X, DVec3::Z];
        turns.add([0, 0, 0], flat, tilted);
        turns.add([1, 1, 1], flat, flat);
        // A custom normal leaning 45 degrees from the face normal keeps its lean.
        let lean = [0.0, (0.5f32).sqrt(), (0.5f32).sqrt()];
        let turned = turns.turn(0).unwrap().normal(lean);
        let expected = [0.0, -(0.5f32).sqrt(), (0.5f32).sqrt()];
        for axis in 0..3 {
            assert!((turned[axis] - expected[axis]).abs() < 1e-6, "{turned:?}");
        }
        assert!(turns.turn(1).is_none());
        assert!(turns.turn(2).is_none(), "a normal no face uses stays");
    }

    #[test]
    fn smooth_groups_join_equal_normals_on_one_vertex_only() {
        let mut groups = SmoothGroups::default();
        let up = [0.0, 0.0, 1.0];
        let side = [1.0, 0.0, 0.0];
        let a = groups.slot(Some(4), up);
        assert_eq!(groups.slot(Some(4), up), a, "a seam copy shares its slot");
        assert_ne!(groups.slot(Some(4), side), a, "a hard edge does not");
        assert_ne!(groups.slot(Some(5), up), a, "another vertex does not");
        let lone = groups.slot(None, up);
        assert_ne!(groups.slot(None, up), lone);
        // A normal that is its own faces' normal (flat shading) never shares.
        let flat = groups.slot_for(DVec3::Z * 2.0, Some(4), up);
        assert_ne!(flat, a);
        assert_ne!(groups.slot_for(DVec3::Z, Some(4), up), flat);
        // One smoothed over other faces does.
        assert_eq!(groups.slot_for(DVec3::new(1.0, 0.0, 1.0), Some(4), up), a);
    }

    #[test]
    fn a_normal_of_collapsed_faces_becomes_the_new_face_normal() {
        let mut turns = NormalTurns::new(1);
        let collapsed = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        let opened = [DVec3::ZERO, DVec3::X, DVec3::Y];
        turns.add([0, 0, 0], collapsed, opened);
        assert_eq!(
            turns.turn(0).unwrap().normal([1.0, 0.0, 0.0]),
            [0.0, 0.0, 1.0]
        );
    }

    #[test]
    fn normals_are_unit_and_never_nan() {
        // A degenerate triangle (all corners equal) and two opposite faces sharing a vertex set.
        let mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [5., 5., 5.]],
            vec![[0, 1, 2], [0, 2, 1], [3, 3, 3]],
        );
        for n in unit_vertex_normals(&mesh) {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((length - 1.0).abs() < 1e-6, "{n:?}");
        }
    }
}
