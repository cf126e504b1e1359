//! Where the default's tangential relaxation acts ([`super::Relaxation::WhereNeeded`]).
//!
//! Not from the paper. The normal-projected operator moves every vertex along its normal only;
//! the relaxation ([`super::FairOptions::tangential_relaxation`]) adds a share of the tangential
//! part of its umbrella vector, which evens the triangles out along the surface. Measured on the
//! sixteen meshes of `docs/measurements.md` ("The relaxation where it is needed"), it is needed in
//! two cases and costs shape in a third:
//! - noise that moved the vertices along the surface (every scanner's has some; the set's
//!   isotropic noise): only the relaxation takes it out (the noisy cube ends 0.076 mean edge
//!   lengths from its clean surface with its faces' normals 6° off with it, 0.097 and 30° without);
//! - slivers: a triangle whose smallest height is a fraction of an edge has its normal decided
//!   by how its corners move across that height, and moving them along their own (noisy)
//!   normals leaves it folded. The generated CAD parts' fans of thin triangles (the cube's faces,
//!   the gear's) end with their face normals 2-4 times as far off without relaxation (cube 3.2° →
//!   10.2°), and all of that on the triangles with an angle below 10-20°: on the others the two
//!   are alike. On a smooth surface (fairing without creases) only a folded one needs it: a
//!   thin triangle that lies in its fan (the open mushroom's band of thin triangles round a
//!   tight bend) is left as it is, as relaxing it cuts the bend ([`Slivers`]);
//! - noise across the surface only, on a scan sampled densest where it curves: the relaxation
//!   evens the sampling out and so cuts the curves as chords (bunny10k ends 0.0852 from its
//!   clean surface with it, 0.0780 without).
//!
//! So the default reads, before the first round, how much of the input's noise lies along the
//! surface ([`estimate_tangential_noise`]) and relaxes every vertex by the share
//! [`everywhere_share`] of the weight, reads it again before every later round until the mesh is
//! as even as a relaxed one ([`still_needed_share`]: relaxing on from there only evens the
//! sampling out, as above), and before every round also relaxes fully the vertices with a sliver
//! among their triangles (`fan_sliver_share`: [`sliver_share`] of its quality; without creases
//! times [`fold_share`] of its turn from the fan).
//!
//! # The tangential noise reading
//! Per vertex v with a closed fan: t_v, the tangential part of its umbrella vector (the mean of
//! its neighbours minus x_v, less its part along the area-weighted normal). On a clean mesh t_v
//! says how unevenly the ring is spread, and changes slowly from vertex to vertex; noise along
//! the surface makes it jump. The reading is the robust spread 1.4826·median|r_v| of r_v = t_v −
//! the mean of t over v's neighbours (its part in v's tangent plane), in mean edge lengths, as
//! the noise estimate ([`super::strength`]) reads the normal part. On the set: clean meshes read
//! 0.00-0.38 (a CAD part's regular grid 0.00, bunny10k's uneven sampling 0.38); with noise 0.3
//! along the normals 0.08-0.38 (the clean mesh's own unevenness, and on CAD parts the normals'
//! tilt leaking into the tangent plane); with isotropic noise 0.3 per coordinate 0.57-0.68, at
//! 0.5 0.75-0.81, at 0.1 0.24-0.44. It is read on at most [`TANGENTIAL_SAMPLES`] vertices spread
//! over the numbering, which a median of that many reads to about a percent.

use crate::mesh::{FanRings, Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;

/// At or below this tangential noise reading (mean edge lengths) the relaxation acts on slivers
/// only, unless the reading against the normal one says otherwise ([`TANGENTIAL_RATIO_NONE`]);
/// from [`TANGENTIAL_NOISE_FULL`] on everywhere, and in between on every vertex with the share of
/// the way from one to the other. Between the reading of noise 0.3 along the normals (at most
/// 0.38 on the set) and of isotropic noise 0.3 (at least 0.57).
pub const TANGENTIAL_NOISE_NONE: f64 = 0.40;

/// See [`TANGENTIAL_NOISE_NONE`].
pub const TANGENTIAL_NOISE_FULL: f64 = 0.55;

/// Weak isotropic noise reads low (0.24 on the CAD parts at 0.1 per coordinate), but in every
/// direction alike: its tangential reading is 2.4-4.5 times the normal one ([`super::strength`])
/// on the set at 0.1, 0.3 and 0.5, while noise along the normals reads at most 1.6 times at 0.3
/// and 0.5 (at 0.1 the uneven scans read their own unevenness, up to 3.8 times: they then get
/// the relaxation everywhere as before). At or below this ratio it adds nothing; from
/// [`TANGENTIAL_RATIO_FULL`] on, the relaxation acts everywhere.
pub const TANGENTIAL_RATIO_NONE: f64 = 1.7;

/// See [`TANGENTIAL_RATIO_NONE`].
pub const TANGENTIAL_RATIO_FULL: f64 = 2.3;

/// The normal reading the ratio of [`TANGENTIAL_RATIO_NONE`] is taken against is at least this
/// (mean edge lengths): a mesh with no noise across its surface but some along it (a flat grid
/// jittered in its plane) gets the relaxation everywhere, a clean one with an even sampling (a
/// CAD part's grid, 0.00-0.02) does not, and where there is no normal reading (a fixed strength
/// without creases) a tangential one above 0.085-0.115 gives the relaxation everywhere, as before.
pub const TANGENTIAL_RATIO_FLOOR: f64 = 0.05;

/// A triangle counts as a sliver below this quality 4√3·area / (sum of the squared edges) (1 for
/// an equilateral triangle, 0 for a degenerate one); the vertices around one are relaxed by the
/// share of the way from here down to [`SLIVER_QUALITY_FULL`], fully below that. (A right
/// isosceles triangle is 0.87; one with a 10° angle between two equal edges about 0.2.)
pub const SLIVER_QUALITY: f32 = 0.5;

/// See [`SLIVER_QUALITY`].
pub const SLIVER_QUALITY_FULL: f32 = 0.3;

/// Without creases ([`Slivers::Folded`]), a thin triangle is relaxed only where it is folded: by
/// the share of the way from here to [`SLIVER_FOLD_FULL_DEGREES`] that its normal turns away from
/// its corner's fan normal (the sum of the fan's area normals), fully beyond. A thin triangle
/// lying in its fan, as the long thin triangles round a smooth scan's tight bend do, is left as it
/// is: relaxing it cuts the bend (`docs/measurements.md`, "Thin triangles along a smooth bend").
pub const SLIVER_FOLD_DEGREES: f32 = 20.0;

/// See [`SLIVER_FOLD_DEGREES`].
pub const SLIVER_FOLD_FULL_DEGREES: f32 = 45.0;

/// Before every later round the tangential noise is read again while the relaxation acts
/// everywhere: at or below this reading the mesh is as even as a relaxed one and the relaxation
/// keeps to the thin triangles from then on; from [`RELAXED_FULL`] on it goes on everywhere. With
/// isotropic noise 0.3 the set's meshes read 0.57-0.68 on the input, 0.18-0.22 after one round
/// and 0.04-0.08 after two (clean CAD parts' grids read 0.00-0.08): any threshold from 0.06 to
/// 0.18 stops it after the second round.
pub const RELAXED: f64 = 0.10;

/// See [`RELAXED`].
pub const RELAXED_FULL: f64 = 0.15;

/// At most this many vertices are read for [`estimate_tangential_noise`].
pub const TANGENTIAL_SAMPLES: usize = 1 << 15;

/// The share of the relaxation's weight every vertex gets for a tangential noise reading and the
/// normal one (the noise estimate, when there is one; see [`TANGENTIAL_NOISE_NONE`],
/// [`TANGENTIAL_RATIO_NONE`] and [`TANGENTIAL_RATIO_FLOOR`]): 1 (everywhere, as with
/// [`super::Relaxation::Everywhere`]) when there is no tangential reading.
pub fn everywhere_share(reading: Option<f64>, normal_noise: Option<f64>) -> f32 {
    let Some(reading) = reading else {
        return 1.0;
    };
    let normal_noise = normal_noise
        .filter(|noise| noise.is_finite())
        .map_or(TANGENTIAL_RATIO_FLOOR, |noise| {
            noise.max(TANGENTIAL_RATIO_FLOOR)
        });
    let by_ratio = ramp(
        reading / normal_noise,
        TANGENTIAL_RATIO_NONE,
        TANGENTIAL_RATIO_FULL,
    );
    ramp(reading, TANGENTIAL_NOISE_NONE, TANGENTIAL_NOISE_FULL).max(by_ratio) as f32
}

/// The share of the relaxation's weight every vertex still gets for the tangential noise read
/// before a later round (see [`RELAXED`]; 1 when there is no reading).
pub fn still_needed_share(reading: Option<f64>) -> f32 {
    reading.map_or(1.0, |reading| ramp(reading, RELAXED, RELAXED_FULL) as f32)
}

/// The share of the relaxation's weight a vertex gets for the least quality among its triangles
/// (see [`SLIVER_QUALITY`]).
#[inline]
pub fn sliver_share(least_quality: f32) -> f32 {
    ramp(
        least_quality as f64,
        SLIVER_QUALITY as f64,
        SLIVER_QUALITY_FULL as f64,
    ) as f32
}

/// The share of the relaxation's weight a thin triangle's fold gives it (see
/// [`SLIVER_FOLD_DEGREES`]), from the cosine of the angle between its normal and its corner's fan
/// normal.
#[inline]
pub fn fold_share(cos_angle: f32) -> f32 {
    let degrees = cos_angle.clamp(-1.0, 1.0).acos().to_degrees();
    ramp(
        degrees as f64,
        SLIVER_FOLD_DEGREES as f64,
        SLIVER_FOLD_FULL_DEGREES as f64,
    ) as f32
}

/// Which thin triangles the relaxation acts on (`fan_sliver_share`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slivers {
    /// Every one: on the flat faces of a CAD part every degree a thin triangle tilts is an error
    /// (the default, with creases).
    All,
    /// Only the folded ones ([`SLIVER_FOLD_DEGREES`]): on a smooth surface a thin triangle may
    /// lie along a bend (without creases).
    Folded,
}

/// The share of the relaxation's weight the point of a fan gets for its thin triangles: the
/// largest, over the fan's triangles, of [`sliver_share`] of its quality, times, with
/// [`Slivers::Folded`], [`fold_share`] of its turn from the fan's normal. `edges` are the fan's
/// edges from the point in fan order, each making a triangle with the one before it, the first
/// with `last` (the fan's last edge, for a closed fan). A triangle with no area, or a fan whose
/// normal vanishes, counts as folded. Runs over every vertex before every round: a fan with no
/// thin triangle costs one division per triangle, no root, and its normal is summed only for a
/// thin triangle.
#[inline]
pub(crate) fn fan_sliver_share(
    last: Vec3A,
    edges: impl Iterator<Item = Vec3A> + Clone,
    slivers: Slivers,
) -> f32 {
    // Squared quality over 12 below which a triangle is thin.
    const THIN: f32 = SLIVER_QUALITY * SLIVER_QUALITY / 12.0;
    // The fan's unit normal, summed only once a thin triangle asks for it (most fans have none).
    let mut normal = None;
    let mut share = 0.0f32;
    let mut previous = last;
    for current in edges.clone() {
        if let Some(squared) = squared_quality_over_12(previous, current) {
            let thin = if squared < THIN {
                sliver_share((12.0 * squared).sqrt())
            } else {
                0.0
            };
            if thin > share {
                let fold = match slivers {
                    Slivers::All => 1.0,
                    Slivers::Folded => {
                        let normal = *normal.get_or_insert_with(|| fan_normal(last, edges.clone()));
                        fold_share(previous.cross(current).normalize_or_zero().dot(normal))
                    }
                };
                share = share.max(thin * fold);
            }
        }
        previous = current;
    }
    share
}

/// The unit normal of a fan (the sum of its triangles' area normals; zero if that vanishes), its
/// edges as [`fan_sliver_share`] takes them.
fn fan_normal(last: Vec3A, edges: impl Iterator<Item = Vec3A>) -> Vec3A {
    let mut previous = last;
    let mut normal = Vec3A::ZERO;
    for current in edges {
        normal += previous.cross(current);
        previous = current;
    }
    normal.normalize_or_zero()
}

/// |a × b|² / (|a|² + |b|² + |b − a|²)², the squared [`triangle_quality`] over 12 of the triangle
/// with edges a and b from one corner (no root); `None` for a triangle with no length. (Dividing
/// twice keeps the terms near the squared edge lengths, far from f32's range.)
#[inline]
fn squared_quality_over_12(a: Vec3A, b: Vec3A) -> Option<f32> {
    let sum = a.length_squared() + b.length_squared() + (b - a).length_squared();
    (sum > 0.0).then(|| a.cross(b).length_squared() / sum / sum)
}

/// 0 at `none`, 1 at `full` and beyond, linear in between (`full` may lie below `none`).
#[inline]
fn ramp(value: f64, none: f64, full: f64) -> f64 {
    ((value - none) / (full - none)).clamp(0.0, 1.0)
}

/// The quality 4√3·area / (|a|² + |b|² + |b − a|²) of the triangle with edges a and b from one
/// corner (see [`SLIVER_QUALITY`]); 1 for a degenerate triangle with no length, which is no sliver
/// to even out.
pub fn triangle_quality(a: Vec3A, b: Vec3A) -> f32 {
    squared_quality_over_12(a, b).map_or(1.0, |squared| (12.0 * squared).sqrt())
}

/// How much of `mesh`'s noise lies along its surface, in mean edge lengths (see the module
/// docs); `None` when fewer than 16 vertices can be read (a vertex and all its neighbours need a
/// closed fan). The same value for any thread count.
pub fn estimate_tangential_noise(mesh: &TriMesh, topology: &Topology) -> Option<f64> {
    read_tangential_noise(mesh, topology, &FanRings::new(&mesh.triangles, topology))
}

/// [`estimate_tangential_noise`] with the fan-ordered one-rings the caller has.
pub(crate) fn read_tangential_noise(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
) -> Option<f64> {
    let offsets = topology.neighbor_csr().0;
    let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
    let ring = |v: u32| &fans.ring[offsets[v as usize] as usize..offsets[v as usize + 1] as usize];
    // A vertex's tangential umbrella part and unit normal.
    let fan = |v: u32| -> Option<(Vec3A, Vec3A)> {
        if !fans.closed_fan[v as usize] {
            return None;
        }
        let ring = ring(v);
        let x = point(v);
        let mut previous = point(*ring.last()?) - x;
        let (mut offset, mut normal) = (Vec3A::ZERO, Vec3A::ZERO);
        for &u in ring {
            let d = point(u) - x;
            offset += d;
            normal += previous.cross(d);
            previous = d;
        }
        let normal = normal.try_normalize()?;
        let umbrella = offset / ring.len() as f32;
        Some((umbrella - normal * normal.dot(umbrella), normal))
    };
    let n = mesh.positions.len();
    let stride = n.div_ceil(TANGENTIAL_SAMPLES).max(1);
    // Per sampled vertex: |r_v| and its ring's edge lengths (summed) and count, when it can be
    // read. (Only the sampled vertex's own ring lengths count for the mean edge length, so they
    // are not summed for each of its neighbours.)
    let read: Vec<(f32, f32, usize)> = (0..n.div_ceil(stride))
        .into_par_iter()
        .with_min_len(256)
        .filter_map(|i| {
            let v = (i * stride) as u32;
            let (t, normal) = fan(v)?;
            let ring = ring(v);
            let mut sum = Vec3A::ZERO;
            for &u in ring {
                sum += fan(u)?.0;
            }
            let r = t - sum / ring.len() as f32;
            let r = r - normal * normal.dot(r);
            let x = point(v);
            let lengths = ring.iter().map(|&u| (point(u) - x).length()).sum::<f32>();
            Some((r.length(), lengths, ring.len()))
        })
        .collect();
    if read.len() < 16 {
        return None;
    }
    let edge = read.iter().map(|&(_, l, _)| l as f64).sum::<f64>()
        / read.iter().map(|&(_, _, k)| k).sum::<usize>() as f64;
    let mut residuals: Vec<f32> = read.iter().map(|&(r, _, _)| r).collect();
    let middle = residuals.len() / 2;
    let median = *residuals.select_nth_unstable_by(middle, f32::total_cmp).1 as f64;
    let reading = 1.4826 * median / edge;
    (edge > 0.0 && reading.is_finite()).then_some(reading)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    use crate::noise::{add_noise, NoiseMode, NoiseOptions};

    fn reading(mesh: &TriMesh) -> f64 {
        estimate_tangential_noise(mesh, &Topology::build(mesh)).unwrap()
    }

    #[test]
    fn the_reading_tells_noise_along_the_surface_from_noise_across_it() {
        let clean = shapes::cylinder(0.5, 1.5, 0.05);
        let noisy = |mode| {
            let mut mesh = clean.clone();
            add_noise(&mut mesh, &NoiseOptions::default().with_mode(mode));
            reading(&mesh)
        };
        let (clean_reading, across, along) = (
            reading(&clean),
            noisy(NoiseMode::Normal),
            noisy(NoiseMode::Isotropic),
        );
        assert!(clean_reading < 0.05, "{clean_reading}");
        assert!(across < TANGENTIAL_NOISE_NONE, "{across}");
        assert!(along > TANGENTIAL_NOISE_FULL, "{along}");
        assert_eq!(everywhere_share(Some(across), Some(0.3)), 0.0);
        assert_eq!(everywhere_share(Some(along), Some(0.3)), 1.0);
        assert_eq!(everywhere_share(None, Some(0.3)), 1.0);
        // Weak noise in every direction: low, but high against the normal part.
        assert_eq!(everywhere_share(Some(0.24), Some(0.3)), 0.0);
        assert_eq!(everywhere_share(Some(0.24), Some(0.1)), 1.0);
        // No noise across the surface: any along it is noise to even out, but a clean mesh's
        // even sampling is not.
        assert_eq!(everywhere_share(Some(0.24), Some(0.0)), 1.0);
        assert_eq!(everywhere_share(Some(0.24), None), 1.0);
        assert_eq!(everywhere_share(Some(0.02), Some(0.0)), 0.0);
        // Read again after rounds of relaxation: noise left, or an even mesh.
        assert_eq!(still_needed_share(Some(0.2)), 1.0);
        assert_eq!(still_needed_share(Some(0.06)), 0.0);
        assert_eq!(still_needed_share(None), 1.0);
    }

    #[test]
    fn slivers_get_the_relaxation_and_fair_triangles_do_not() {
        let equilateral = triangle_quality(Vec3A::X, Vec3A::new(0.5, 0.75f32.sqrt(), 0.0));
        assert!((equilateral - 1.0).abs() < 1e-6, "{equilateral}");
        assert_eq!(sliver_share(equilateral), 0.0);
        let sliver = triangle_quality(Vec3A::X, Vec3A::new(0.5, 0.05, 0.0));
        assert!(sliver < SLIVER_QUALITY_FULL, "{sliver}");
        assert_eq!(sliver_share(sliver), 1.0);
        let between = (SLIVER_QUALITY + SLIVER_QUALITY_FULL) / 2.0;
        assert!((sliver_share(between) - 0.5).abs() < 1e-6);
        assert_eq!(triangle_quality(Vec3A::ZERO, Vec3A::ZERO), 1.0);
    }

    #[test]
    fn without_creases_thin_triangles_get_the_relaxation_only_where_they_fold() {
        use Slivers::Folded;
        assert_eq!(
            fold_share(SLIVER_FOLD_DEGREES.to_radians().cos() + 1e-4),
            0.0
        );
        assert_eq!(
            fold_share(SLIVER_FOLD_FULL_DEGREES.to_radians().cos() - 1e-4),
            1.0
        );
        let middle = (SLIVER_FOLD_DEGREES + SLIVER_FOLD_FULL_DEGREES) / 2.0;
        assert!((fold_share(middle.to_radians().cos()) - 0.5).abs() < 1e-3);
        // A flat fan around the origin, its second triangle (between x and `thin`) a sliver.
        let fan = |thin: Vec3A| [Vec3A::X, thin, Vec3A::Y, -Vec3A::X, -Vec3A::Y];
        let share = |edges: [Vec3A; 5]| fan_sliver_share(edges[4], edges.into_iter(), Folded);
        let with_creases =
            |edges: [Vec3A; 5]| fan_sliver_share(edges[4], edges.into_iter(), Slivers::All);
        let flat = fan(Vec3A::new(1.0, 0.05, 0.0));
        assert!(triangle_quality(flat[0], flat[1]) < SLIVER_QUALITY_FULL);
        assert_eq!(share(flat), 0.0, "a sliver lying in its fan is left alone");
        assert_eq!(
            with_creases(flat),
            1.0,
            "with creases every sliver is relaxed"
        );
        // The sliver's far corner lifted: still as thin, its normal 63° off the fan's.
        let folded = fan(Vec3A::new(1.0, 0.05, 0.1));
        assert!(triangle_quality(folded[0], folded[1]) < SLIVER_QUALITY_FULL);
        assert_eq!(share(folded), 1.0, "a folded sliver is relaxed");
        // Lifted less, its normal turns ~27°: part of the weight.
        let tilted = share(fan(Vec3A::new(1.0, 0.05, 0.025)));
        assert!(tilted > 0.0 && tilted < 1.0, "{tilted}");
        // A fan of fair triangles gets nothing however bent.
        let bent = [Vec3A::X, Vec3A::new(0.0, 1.0, 0.8), -Vec3A::X, -Vec3A::Y];
        for slivers in [Folded, Slivers::All] {
            assert_eq!(fan_sliver_share(bent[3], bent.into_iter(), slivers), 0.0);
        }
        // A triangle with no area is a fold.
        let collapsed = fan(Vec3A::new(2.0, 0.0, 0.0));
        assert_eq!(share(collapsed), 1.0);
    }
}
