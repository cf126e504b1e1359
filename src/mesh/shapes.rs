//! CAD-like test shapes with sharp edges: prisms made by extruding a closed outline (a square, a
//! circle, a gear, a D made of a half-disc on a rectangle), with evenly sampled sides and caps;
//! CAD parts as exporters write them; and, for contrast, a smooth icosphere and a flat grid.
//!
//! Not part of the paper: the fairing's crease handling and its clean-mesh bounds are measured on
//! these (the tests, `examples/fairing_quality.rs`), since scanned meshes have few sharp edges.
//!
//! A prism's side is a grid of `layers` rows between the two copies of the outline; each cap is a
//! set of concentric copies of the outline shrunk towards its centroid (so the outline must be
//! star-shaped about its centroid), joined by quads and a fan around the centre. Every triangle is
//! oriented outwards; the mesh is closed, manifold and of genus 0.

use super::TriMesh;
use std::f64::consts::TAU;

/// Extrudes `outline` (counter-clockwise, star-shaped about its centroid, in the xy plane) from
/// z = 0 to z = `height`: `layers` rows of quads on the side, `rings` rings on each cap.
pub fn extrusion(outline: &[[f64; 2]], height: f64, layers: usize, rings: usize) -> TriMesh {
    let m = outline.len();
    let (layers, rings) = (layers.max(1), rings.max(1));
    let centre = outline
        .iter()
        .fold([0.0, 0.0], |s, p| [s[0] + p[0], s[1] + p[1]])
        .map(|c| c / m as f64);
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let ring_at = |scale: f64, z: f64, positions: &mut Vec<[f32; 3]>| -> u32 {
        let start = positions.len() as u32;
        for p in outline {
            let x = centre[0] + (p[0] - centre[0]) * scale;
            let y = centre[1] + (p[1] - centre[1]) * scale;
            positions.push([x as f32, y as f32, z as f32]);
        }
        start
    };
    // Quads between two rings a -> b (b above a, or b inside a on a cap), outward when `flip` is
    // false for the side (counter-clockwise outline seen from outside).
    let join = |a: u32, b: u32, flip: bool, triangles: &mut Vec<[u32; 3]>| {
        for i in 0..m as u32 {
            let j = (i + 1) % m as u32;
            let (t1, t2) = ([a + i, a + j, b + j], [a + i, b + j, b + i]);
            if flip {
                triangles.push([t1[0], t1[2], t1[1]]);
                triangles.push([t2[0], t2[2], t2[1]]);
            } else {
                triangles.push(t1);
                triangles.push(t2);
            }
        }
    };
    let side: Vec<u32> = (0..=layers)
        .map(|k| ring_at(1.0, height * k as f64 / layers as f64, &mut positions))
        .collect();
    for k in 0..layers {
        join(side[k], side[k + 1], false, &mut triangles);
    }
    for (outer, z, top) in [(side[layers], height, true), (side[0], 0.0, false)] {
        let mut previous = outer;
        for r in 1..rings {
            let ring = ring_at(1.0 - r as f64 / rings as f64, z, &mut positions);
            // Seen from above, the outline runs counter-clockwise: a quad (outer i, outer j,
            // inner j, inner i) faces up.
            join(previous, ring, !top, &mut triangles);
            previous = ring;
        }
        let c = positions.len() as u32;
        positions.push([centre[0] as f32, centre[1] as f32, z as f32]);
        for i in 0..m as u32 {
            let j = (i + 1) % m as u32;
            triangles.push(if top {
                [previous + i, previous + j, c]
            } else {
                [previous + j, previous + i, c]
            });
        }
    }
    TriMesh::new(positions, triangles)
}

/// `count` points evenly spaced along the closed polyline `corners` (counter-clockwise), the
/// corners themselves among them where the spacing allows (each side gets its share by length).
pub fn resample_closed(corners: &[[f64; 2]], count: usize) -> Vec<[f64; 2]> {
    let n = corners.len();
    let length = |i: usize| {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
    };
    let total: f64 = (0..n).map(length).sum();
    let mut points = Vec::with_capacity(count);
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        let pieces = ((length(i) / total * count as f64).round() as usize).max(1);
        for k in 0..pieces {
            let t = k as f64 / pieces as f64;
            points.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    points
}

/// [`extrusion`] of `outline` sampled about every `spacing`: as many side rows as fit in
/// `height`, as many cap rings as fit in `cap_radius`.
fn prism(outline: &[[f64; 2]], height: f64, spacing: f64, cap_radius: f64) -> TriMesh {
    let layers = (height / spacing).round() as usize;
    let rings = (cap_radius / spacing).round() as usize;
    extrusion(outline, height, layers, rings)
}

/// A box of `size` (x, y, z) with sides sampled about every `spacing`.
pub fn cuboid(size: [f64; 3], spacing: f64) -> TriMesh {
    let square = [
        [0.0, 0.0],
        [size[0], 0.0],
        [size[0], size[1]],
        [0.0, size[1]],
    ];
    let perimeter = 2.0 * (size[0] + size[1]);
    let outline = resample_closed(&square, (perimeter / spacing).round() as usize);
    prism(&outline, size[2], spacing, size[0].min(size[1]) / 2.0)
}

/// A closed cylinder of `radius` and `height`, sampled about every `spacing`.
pub fn cylinder(radius: f64, height: f64, spacing: f64) -> TriMesh {
    let m = ((TAU * radius / spacing).round() as usize).max(3);
    let outline: Vec<[f64; 2]> = (0..m)
        .map(|i| {
            let a = TAU * i as f64 / m as f64;
            [radius * a.cos(), radius * a.sin()]
        })
        .collect();
    prism(&outline, height, spacing, radius)
}

/// A spur gear: `teeth` trapezoidal teeth between `root` and `tip` radius, `height` thick.
pub fn gear(teeth: usize, root: f64, tip: f64, height: f64, spacing: f64) -> TriMesh {
    let mut corners = Vec::new();
    for t in 0..teeth {
        let a = TAU * t as f64 / teeth as f64;
        let step = TAU / teeth as f64;
        for (fraction, radius) in [(0.0, root), (0.2, tip), (0.45, tip), (0.65, root)] {
            let angle = a + fraction * step;
            corners.push([radius * angle.cos(), radius * angle.sin()]);
        }
    }
    let perimeter: f64 = (0..corners.len())
        .map(|i| {
            let (a, b) = (corners[i], corners[(i + 1) % corners.len()]);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
        })
        .sum();
    let outline = resample_closed(&corners, (perimeter / spacing).round() as usize);
    prism(&outline, height, spacing, root)
}

/// A D-shaped prism: a half-disc of `radius` on a rectangle `2·radius` wide and `depth` deep,
/// `height` thick: flat, sharp and smoothly curved regions side by side (like the fandisk).
pub fn d_prism(radius: f64, depth: f64, height: f64, spacing: f64) -> TriMesh {
    let arc_points = ((std::f64::consts::PI * radius / spacing).round() as usize).max(2);
    let mut corners = vec![[-radius, -depth], [radius, -depth]];
    for k in 0..=arc_points {
        let a = std::f64::consts::PI * k as f64 / arc_points as f64;
        corners.push([radius * a.cos(), radius * a.sin()]);
    }
    corners.dedup();
    let perimeter = std::f64::consts::PI * radius + 2.0 * (radius + depth) + 2.0 * radius;
    let outline = resample_closed(&corners, (perimeter / spacing).round() as usize);
    prism(&outline, height, spacing, radius)
}

/// A closed cylinder as CAD exporters write it: `segments` vertices on each rim and no others,
/// each side quad one pair of triangles spanning the whole `height`, each cap a fan of slivers
/// from one rim vertex. Few vertices, long thin triangles: a clean mesh that the noise estimate
/// must not read as noisy.
pub fn cad_cylinder(segments: usize, radius: f64, height: f64) -> TriMesh {
    let n = segments.max(3);
    let mut positions = Vec::with_capacity(2 * n);
    for z in [0.0, height] {
        for i in 0..n {
            let a = TAU * i as f64 / n as f64;
            positions.push([
                (radius * a.cos()) as f32,
                (radius * a.sin()) as f32,
                z as f32,
            ]);
        }
    }
    let mut triangles = Vec::with_capacity(4 * n - 4);
    for i in 0..n {
        let j = (i + 1) % n;
        let (i, j, m) = (i as u32, j as u32, n as u32);
        triangles.push([i, j, m + j]);
        triangles.push([i, m + j, m + i]);
    }
    for i in 1..n as u32 - 1 {
        let m = n as u32;
        triangles.push([0, i + 1, i]);
        triangles.push([m, m + i, m + i + 1]);
    }
    TriMesh::new(positions, triangles)
}

/// An open-topped box with thin walls and a round hole through each wall, as CAD exporters write
/// it: `size` outside (x, y, z; open at z = `size[2]`), walls and floor `wall` thick, each hole
/// of `radius` with `segments` sides (rounded up to a multiple of 4) centred halfway up its wall.
/// Each flat face has only its corners and its hole's vertices, the hole's rim joined to the
/// nearest corner by fans of long thin triangles; each hole's tunnel is one quad (two triangles)
/// per side. Closed, oriented outwards, genus 4 (one handle per hole).
pub fn cad_box_with_holes(size: [f64; 3], wall: f64, radius: f64, segments: usize) -> TriMesh {
    let sides = segments.max(4).div_ceil(4) * 4;
    let [w, d, _] = size.map(|x| x / 2.0);
    let mut shape = Faces::default();
    // The floor underneath and on top, and the rim between the outer and inner top edges.
    let (inner_w, inner_d) = (w - wall, d - wall);
    let corners = |a: f64, b: f64, z: f64| [[-a, -b, z], [a, -b, z], [a, b, z], [-a, b, z]];
    let bottom = corners(w, d, 0.0);
    shape.polygon(&bottom, [0.0, 0.0, -1.0]);
    shape.polygon(&corners(inner_w, inner_d, wall), [0.0, 0.0, 1.0]);
    let (outer_top, inner_top) = (corners(w, d, size[2]), corners(inner_w, inner_d, size[2]));
    for k in 0..4 {
        let l = (k + 1) % 4;
        shape.polygon(
            &[outer_top[k], outer_top[l], inner_top[l], inner_top[k]],
            [0.0, 0.0, 1.0],
        );
    }
    // The walls: (outward normal, the wall's horizontal direction, its half width outside and
    // inside, its distance from the centre outside).
    let walls = [
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], w, inner_w, d),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], d, inner_d, w),
        ([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], w, inner_w, d),
        ([-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], d, inner_d, w),
    ];
    let at = |normal: [f64; 3], along: [f64; 3], distance: f64, u: f64, z: f64| {
        [0, 1, 2].map(|i| normal[i] * distance + along[i] * u + if i == 2 { z } else { 0.0 })
    };
    let centre_z = size[2] / 2.0;
    for (normal, along, half, inner_half, distance) in walls {
        let hole = |distance: f64| -> Vec<[f64; 3]> {
            (0..sides)
                .map(|i| {
                    let a = TAU * (i as f64 + 0.5) / sides as f64;
                    at(
                        normal,
                        along,
                        distance,
                        radius * a.cos(),
                        centre_z + radius * a.sin(),
                    )
                })
                .collect()
        };
        let (outer_hole, inner_hole) = (hole(distance), hole(distance - wall));
        // Corners counter-clockwise seen from outside, from the upper one in the first quadrant.
        let outer = [(half, size[2]), (-half, size[2]), (-half, 0.0), (half, 0.0)]
            .map(|(u, z)| at(normal, along, distance, u, z));
        let inner = [(inner_half, size[2]), (-inner_half, size[2])]
            .into_iter()
            .chain([(-inner_half, wall), (inner_half, wall)])
            .map(|(u, z)| at(normal, along, distance - wall, u, z))
            .collect::<Vec<_>>();
        let inward = normal.map(|x| -x);
        shape.face_with_hole(&outer, &outer_hole, normal);
        shape.face_with_hole(&inner, &inner_hole, inward);
        // The tunnel, facing the hole's axis.
        for i in 0..sides {
            let j = (i + 1) % sides;
            let axis = at(normal, along, distance, 0.0, centre_z);
            let facing = [0, 1, 2].map(|k| axis[k] - outer_hole[i][k]);
            shape.polygon(
                &[outer_hole[i], outer_hole[j], inner_hole[j], inner_hole[i]],
                [facing[0], facing[1], facing[2]],
            );
        }
    }
    shape.mesh()
}

/// Faces given by their corners, vertices shared where positions are equal, each triangle turned
/// to face the way its face is meant to.
#[derive(Default)]
struct Faces {
    positions: Vec<[f32; 3]>,
    index: std::collections::HashMap<[u32; 3], u32>,
    triangles: Vec<[u32; 3]>,
}

impl Faces {
    fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let p = p.map(|x| x as f32);
        let next = self.positions.len() as u32;
        let index = *self.index.entry(p.map(f32::to_bits)).or_insert(next);
        if index == next {
            self.positions.push(p);
        }
        index
    }

    fn triangle(&mut self, corners: [[f64; 3]; 3], facing: [f64; 3]) {
        let [a, b, c] = corners;
        let (e, f) = (
            [0, 1, 2].map(|i| b[i] - a[i]),
            [0, 1, 2].map(|i| c[i] - a[i]),
        );
        let n = [
            e[1] * f[2] - e[2] * f[1],
            e[2] * f[0] - e[0] * f[2],
            e[0] * f[1] - e[1] * f[0],
        ];
        let along = n[0] * facing[0] + n[1] * facing[1] + n[2] * facing[2];
        let corners = if along < 0.0 { [a, c, b] } else { [a, b, c] };
        let triangle = corners.map(|p| self.vertex(p));
        self.triangles.push(triangle);
    }

    /// A convex polygon, fanned from its first corner.
    fn polygon(&mut self, corners: &[[f64; 3]], facing: [f64; 3]) {
        for k in 1..corners.len() - 1 {
            self.triangle([corners[0], corners[k], corners[k + 1]], facing);
        }
    }

    /// A rectangle (`corners` counter-clockwise, the first in the first quadrant seen from the
    /// hole's centre) with a convex hole (`hole` counter-clockwise, a quarter of its vertices in
    /// each quadrant), each of the hole's vertices joined to the corner of its quadrant, and each
    /// side to the hole's first vertex past it.
    fn face_with_hole(&mut self, corners: &[[f64; 3]], hole: &[[f64; 3]], facing: [f64; 3]) {
        let quarter = hole.len() / 4;
        for i in 0..hole.len() {
            let j = (i + 1) % hole.len();
            let (q, next) = (i / quarter, j / quarter);
            self.triangle([hole[i], corners[q], hole[j]], facing);
            if next != q {
                self.triangle([corners[q], corners[next], hole[j]], facing);
            }
        }
    }

    fn mesh(self) -> TriMesh {
        TriMesh::new(self.positions, self.triangles)
    }
}

/// A flat grid of `n`×`n` squares of side 1 in the plane z = 0, each cut into two triangles
/// (valence 6 inside); vertex (x, y) is y·(n + 1) + x.
pub fn grid(n: usize) -> TriMesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push([x as f32, y as f32, 0.0]);
        }
    }
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            triangles.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
            triangles.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    TriMesh::new(positions, triangles)
}

/// A unit icosphere, a smooth shape with no sharp edge: an icosahedron, each triangle split in
/// four `levels` times, every new vertex projected to the unit sphere (computed in f64).
pub fn icosphere(levels: usize) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let normalize = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|x| x / l)
    };
    for p in &mut positions {
        *p = normalize(*p);
    }
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints: std::collections::HashMap<(u32, u32), u32> =
            std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                positions.push(normalize(std::array::from_fn(|k| pa[k] + pb[k])));
                positions.len() as u32 - 1
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            finer.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    TriMesh::new(
        positions.iter().map(|p| p.map(|x| x as f32)).collect(),
        triangles,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;

    #[test]
    fn shapes_are_closed_oriented_genus_zero_and_outward() {
        for (name, mesh) in [
            ("cuboid", cuboid([2.0, 1.0, 0.5], 0.1)),
            ("cylinder", cylinder(1.0, 2.0, 0.15)),
            ("gear", gear(12, 1.0, 1.3, 0.4, 0.06)),
            ("d", d_prism(1.0, 0.8, 0.6, 0.1)),
            ("cad cylinder", cad_cylinder(32, 0.5, 1.5)),
            ("icosphere", icosphere(2)),
        ] {
            let topology = Topology::build(&mesh);
            assert!(topology.is_closed(), "{name}");
            assert!(topology.is_oriented_manifold(), "{name}");
            assert_eq!(topology.euler_characteristic(), 2, "{name}");
            assert!(crate::metrics::signed_volume(&mesh) > 0.0, "{name}");
        }
        // Four holes: four handles. The volume is the walls' and the floor's, less the holes'.
        let (size, wall, radius) = ([2.0, 1.4, 1.0], 0.05, 0.25);
        let part = cad_box_with_holes(size, wall, radius, 24);
        let topology = Topology::build(&part);
        assert!(topology.is_closed() && topology.is_oriented_manifold());
        assert_eq!(topology.euler_characteristic(), 2 - 2 * 4);
        let solid = size[0] * size[1] * size[2]
            - (size[0] - 2.0 * wall) * (size[1] - 2.0 * wall) * (size[2] - wall);
        let holes = 4.0 * wall * 24.0 / 2.0 * radius * radius * (TAU / 24.0).sin();
        let volume = crate::metrics::signed_volume(&part);
        assert!(
            (volume - (solid - holes)).abs() < 1e-4,
            "{volume} against {}",
            solid - holes
        );
        // Every vertex on the unit sphere, each level four times the faces.
        let ball = icosphere(2);
        assert_eq!(ball.triangles.len(), 20 * 16);
        for p in &ball.positions {
            let length = p.iter().map(|x| x * x).sum::<f32>().sqrt();
            assert!((length - 1.0).abs() < 1e-6, "{p:?}");
        }
        let size = [2.0, 1.0, 0.5];
        let volume = crate::metrics::signed_volume(&cuboid(size, 0.1));
        assert!((volume - 1.0).abs() < 1e-5, "cuboid volume {volume}");
    }
}
