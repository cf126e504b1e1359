//! Turning a written-back document's NORMAL and TANGENT elements with their faces (see
//! [`crate::io::normals::NormalTurns`]): per element the area sums of its faces before and after,
//! worked out block by block in parallel with the same bits for any number of threads.

use super::accessors::Layout;
use super::buffers::Joined;
use super::positions::PositionEdit;
use super::source::{attribute, primitives, GltfSource};
use crate::io::normals::{dvec, is_own_normal, NormalTurns, SlotSums, SmoothGroups, Turn};
use crate::io::origin::Origin;
use crate::io::SaveReport;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// Turn the NORMAL (and TANGENT) elements of every primitive whose faces moved. Normals of all
/// accessors share slots by welded vertex and value ([`SmoothGroups`]), so a smooth normal split
/// at a UV seam or between two primitives stays smooth.
pub(super) fn turn_normals(
    gltf: &GltfSource,
    origin: &Origin,
    edits: &BTreeMap<usize, PositionEdit>,
    joined: &mut Joined,
    report: &mut SaveReport,
) -> BTreeSet<usize> {
    let normals = normal_uses(gltf, edits, report);
    let (slotted, shared) = slot_normals(gltf, origin, edits, &normals);
    let mut changed = BTreeSet::new();
    for normal in slotted {
        write_turned(gltf, normal, &shared, joined, &mut changed, report);
    }
    changed
}

/// The triangles of the primitives that use one normal accessor: per primitive, its position
/// accessor, that accessor's layout and the triangles.
type Uses = Vec<(usize, Layout, Vec<[u32; 3]>)>;

/// Normal accessor (of a primitive whose positions moved) -> its layout, its [`Uses`], and its
/// tangent accessors. One that cannot be read or does not match its positions is named in the
/// report and left out.
fn normal_uses(
    gltf: &GltfSource,
    edits: &BTreeMap<usize, PositionEdit>,
    report: &mut SaveReport,
) -> BTreeMap<usize, (Layout, Uses, BTreeSet<usize>)> {
    let touched: BTreeSet<usize> = primitives(&gltf.json)
        .filter(|p| attribute(p, "POSITION").is_some_and(|a| edits.contains_key(&a)))
        .filter_map(|p| attribute(p, "NORMAL"))
        .collect();
    let mut normals: BTreeMap<usize, (Layout, Uses, BTreeSet<usize>)> = BTreeMap::new();
    for primitive in primitives(&gltf.json) {
        let (Some(p), Some(n)) = (
            attribute(primitive, "POSITION"),
            attribute(primitive, "NORMAL"),
        ) else {
            continue;
        };
        if !touched.contains(&n) {
            continue;
        }
        let (Ok(layout), Ok(positions)) = (gltf.layout(n), gltf.layout(p)) else {
            report.warnings.push(format!(
                "normal accessor {n} cannot be read: its normals were not turned"
            ));
            continue;
        };
        if layout.components != 3 || layout.count != positions.count {
            report.warnings.push(format!(
                "normal accessor {n} does not match its positions: its normals were not turned"
            ));
            continue;
        }
        let (_, uses, tangents) = normals
            .entry(n)
            .or_insert_with(|| (layout, Vec::new(), BTreeSet::new()));
        uses.push((p, positions, gltf.triangles(primitive, positions.count)));
        if let Some(t) = attribute(primitive, "TANGENT") {
            tangents.insert(t);
        }
    }
    normals
}

/// Per element: the area sums of its faces before and after, block by block in parallel
/// (`block_sums`: each element adds its faces in the order of the triangles, as a serial pass
/// would). A normal that is its own faces' normal turns with its own sums, worked out in the
/// same block; the others (`SmoothGroups`) share the sums of their slot, gathered in the
/// returned [`NormalTurns`] in the order of the elements and turned once every accessor has
/// added to them.
fn slot_normals<'a>(
    gltf: &GltfSource,
    origin: &Origin,
    edits: &BTreeMap<usize, PositionEdit>,
    normals: &'a BTreeMap<usize, (Layout, Uses, BTreeSet<usize>)>,
) -> (Vec<Slotted<'a>>, NormalTurns) {
    let mut groups = SmoothGroups::default();
    let mut shared = NormalTurns::new(0);
    let mut slotted: Vec<Slotted> = Vec::new();
    for (&n, (layout, uses, tangents)) in normals {
        let faces: Vec<FaceUse> = uses
            .iter()
            .map(|(p, positions, triangles)| match edits.get(p) {
                Some(edit) => FaceUse::new(triangles, &edit.before, Some(&edit.after)),
                None => FaceUse::new(triangles, &gltf.read3_all(positions), None),
            })
            .collect();
        let values = gltf.read3_all(layout);
        let keep_turns = !tangents.is_empty();
        let blocks = block_sums(&faces, layout.count, |first, sums| {
            let mut block = BlockTurns::default();
            for (k, sums) in (first..).zip(sums) {
                let turn = if is_own_normal(sums.area_before(), values[k]) {
                    sums.alone().turn()
                } else {
                    block.shared.push((k, *sums));
                    None
                };
                block.normals.push(turn.map(|turn| turn.normal(values[k])));
                if keep_turns {
                    block.turns.push(turn);
                }
            }
            block
        });
        let start = gltf.first_raw_start(uses[0].0);
        let mut slots = Vec::new();
        for &(k, sums) in blocks.iter().flat_map(|block| &block.shared) {
            let welded = start.and_then(|s| origin.welded(s + k));
            let slot = groups.slot(welded, values[k]);
            shared.merge_sums(slot, sums);
            slots.push((k, slot));
        }
        slotted.push(Slotted {
            accessor: n,
            layout,
            values,
            blocks,
            slots,
            tangents,
        });
    }
    (slotted, shared)
}

/// Writes one normal accessor's turned normals (its own, and those of the `shared` slots) and
/// its tangents turned alike; the accessors written go into `changed`.
fn write_turned(
    gltf: &GltfSource,
    normal: Slotted,
    shared: &NormalTurns,
    joined: &mut Joined,
    changed: &mut BTreeSet<usize>,
    report: &mut SaveReport,
) {
    let layout = normal.layout;
    let shared_turns: Vec<(usize, Option<Turn>)> = normal
        .slots
        .iter()
        .map(|&(k, slot)| (k, shared.turn(slot)))
        .collect();
    let mut any = false;
    let own = normal.blocks.iter().flat_map(|block| &block.normals);
    for (k, value) in own.enumerate() {
        if let Some(value) = value {
            joined.put_direction(layout, k, value);
            any = true;
        }
    }
    for &(k, turn) in &shared_turns {
        if let Some(turn) = turn {
            joined.put_direction(layout, k, &turn.normal(normal.values[k]));
            any = true;
        }
    }
    if any {
        changed.insert(normal.accessor);
    }
    for &t in normal.tangents {
        match gltf.layout(t) {
            Ok(tangent) if tangent.components == 4 && tangent.count == layout.count => {
                let own = normal.blocks.iter().flat_map(|block| &block.turns);
                let turns = own.copied().enumerate().chain(shared_turns.iter().copied());
                for (k, turn) in turns {
                    if let Some(turn) = turn {
                        let direction = turn.direction(gltf.read3(&tangent, k));
                        joined.put_direction(&tangent, k, &direction);
                    }
                }
                if any {
                    changed.insert(t);
                }
            }
            _ => report.warnings.push(format!(
                "tangent accessor {t} does not match its normals: its tangents were not turned"
            )),
        }
    }
}

/// One block of a normal accessor's elements after [`block_sums`]: per element, the turned
/// normal when it turns with its own faces (`None` when it stays, or shares a slot), the turn
/// itself when the accessor has tangents, and the elements that share a slot with their sums.
#[derive(Default)]
struct BlockTurns {
    normals: Vec<Option<[f32; 3]>>,
    turns: Vec<Option<Turn>>,
    shared: Vec<(usize, SlotSums)>,
}

/// One normal accessor ready to turn: its values, its blocks, and the slot of each element that
/// shares one.
struct Slotted<'a> {
    accessor: usize,
    layout: &'a Layout,
    values: Vec<[f32; 3]>,
    blocks: Vec<BlockTurns>,
    slots: Vec<(usize, usize)>,
    tangents: &'a BTreeSet<usize>,
}

/// The triangles of one primitive that uses a normal accessor, with its positions before and
/// after (`None`: they did not move).
struct FaceUse<'a> {
    triangles: &'a [[u32; 3]],
    /// Per vertex of the primitive, its position before and after, side by side (one place to
    /// read per corner).
    points: Vec<[[f32; 3]; 2]>,
}

impl<'a> FaceUse<'a> {
    fn new(
        triangles: &'a [[u32; 3]],
        before: &[[f32; 3]],
        after: Option<&[Option<[f32; 3]>]>,
    ) -> FaceUse<'a> {
        let points = match after {
            Some(after) => before
                .par_iter()
                .zip(after)
                .with_min_len(4096)
                .map(|(&b, a)| [b, a.unwrap_or(b)])
                .collect(),
            None => before
                .par_iter()
                .with_min_len(4096)
                .map(|&b| [b, b])
                .collect(),
        };
        FaceUse { triangles, points }
    }

    fn corners(&self, t: [u32; 3]) -> ([DVec3; 3], [DVec3; 3]) {
        let points = t.map(|v| self.points[v as usize]);
        (points.map(|p| dvec(p[0])), points.map(|p| dvec(p[1])))
    }
}

/// Per block of a normal accessor's elements (`count` of them; one block per thread),
/// `finish(first element, the block's area sums)`, the blocks worked out in parallel and
/// returned in order. Each element's sums are those of the faces that use it, before and after,
/// added in the order of the uses and their triangles (a face using it twice adds twice), exactly
/// as one serial pass adds them: the same bits for any number of threads. Each block's task goes
/// through all the triangles and adds those with a corner in its block (a triangle across two
/// blocks is worked out in both).
fn block_sums<R: Send>(
    uses: &[FaceUse],
    count: usize,
    finish: impl Fn(usize, &[SlotSums]) -> R + Sync,
) -> Vec<R> {
    let threads = rayon::current_num_threads().max(1);
    let triangles: usize = uses.iter().map(|u| u.triangles.len()).sum();
    let block = if threads == 1 || triangles < 100_000 {
        count.max(1)
    } else {
        count.div_ceil(threads).max(1)
    };
    (0..count.div_ceil(block))
        .into_par_iter()
        .map(|b| {
            let first = b * block;
            let len = block.min(count - first);
            let mut sums = vec![SlotSums::default(); len];
            let ours = |v: u32| (v as usize).wrapping_sub(first) < len;
            for u in uses {
                for &t in u.triangles {
                    if !t.iter().any(|&v| ours(v)) {
                        continue;
                    }
                    let (before, after) = u.corners(t);
                    let add = SlotSums::of_triangle(before, after);
                    for v in t {
                        if ours(v) {
                            sums[v as usize - first].merge(add);
                        }
                    }
                }
            }
            finish(first, &sums)
        })
        .collect()
}
