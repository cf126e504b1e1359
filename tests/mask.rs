//! Masks (fairing only where painted): constrained fairing, multires and the baselines leave the
//! unpainted vertices exactly where they were, move the painted ones, and fade at a soft edge.

use fairmesh::fairing::{
    fair_constrained, fair_masked, FairOptions, LaplacianOptions, Mask, MethodOptions,
};
use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
use fairmesh::multires::{fair_multires, MultiresOptions, MultiresWorkspace};
use fairmesh::noise::{add_noise, NoiseOptions};
use fairmesh::{NoProgress, Topology, TriMesh};

/// The bundled bunny with noise, and the mask of its vertices left of the middle (x below the
/// median).
fn noisy_bunny_and_left_half() -> (TriMesh, TriMesh, Mask) {
    let clean = fairmesh::bundled::load_bunny(&Default::default())
        .unwrap()
        .mesh;
    let mut noisy = clean.clone();
    add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
    let mut xs: Vec<f32> = noisy.positions.iter().map(|p| p[0]).collect();
    xs.sort_by(f32::total_cmp);
    let median = xs[xs.len() / 2];
    let left = noisy
        .positions
        .iter()
        .enumerate()
        .filter(|(_, p)| p[0] < median)
        .map(|(v, _)| v);
    let mask = Mask::from_vertices(noisy.positions.len(), left);
    (clean, noisy, mask)
}

/// Unpainted vertices are bit-identical to `before`; most painted ones moved.
fn check_only_painted_moved(before: &TriMesh, after: &[[f32; 3]], mask: &Mask) {
    let mut moved = 0;
    for (v, (p, q)) in after.iter().zip(&before.positions).enumerate() {
        if mask.weight(v) == 0.0 {
            assert_eq!(p, q, "unpainted vertex {v} moved");
        } else if p != q {
            moved += 1;
        }
    }
    let painted = mask.painted_count();
    assert!(
        moved > painted * 9 / 10,
        "{moved} of {painted} painted moved"
    );
}

fn squared_distance(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3).map(|k| (a[k] as f64 - b[k] as f64).powi(2)).sum()
}

#[test]
fn constrained_fairing_moves_only_the_painted_region_and_removes_its_noise() {
    let (clean, noisy, mask) = noisy_bunny_and_left_half();
    let topology = Topology::build(&noisy);
    let mut faired = noisy.clone();
    let options = FairOptions::default().with_mask(Some(mask.clone()));
    let report = fair_constrained(&mut faired, &topology, &options);
    assert!(report.iterations_run > 0);
    check_only_painted_moved(&noisy, &faired.positions, &mask);
    // The painted half came much closer to the clean bunny's surface (the squared distances
    // summed fall to 7 % of the input's), and about as close as fairing the whole mesh for as
    // many rounds brings it (the automatic stop may pick another round for either, 26 against 28
    // here). Not quite: along the pinned edge the noise of the pinned neighbours stays in the
    // averages (1-2 rings from it the painted vertices end 58 % farther than in the whole mesh's
    // fairing, 3-4 rings 9 %), and farther away the two runs differ by a few percent either way
    // as the creases found and the volume offsets differ; the whole painted half ends 5 % farther
    // (measured in this test's set-up). Distances to the surface, not to each vertex's clean
    // position: the default's tangential relaxation may slide vertices along the surface.
    let surface = fairmesh::metrics::ClosestPointIndex::new(&clean);
    let squared_distances = |positions: &[[f32; 3]]| -> f64 {
        (0..positions.len())
            .filter(|&v| mask.weight(v) > 0.0)
            .map(|v| {
                surface
                    .distance(glam::DVec3::from(positions[v].map(f64::from)))
                    .powi(2)
            })
            .sum()
    };
    let (before, after) = (
        squared_distances(&noisy.positions),
        squared_distances(&faired.positions),
    );
    assert!(after < 0.1 * before, "{after} against {before}");
    let rounds = report.rounds_run;
    let fixed = |mask: Option<fairmesh::fairing::Mask>| {
        let mut mesh = noisy.clone();
        let options = FairOptions::default().with_rounds(rounds).with_mask(mask);
        fair_constrained(&mut mesh, &topology, &options);
        squared_distances(&mesh.positions)
    };
    let (masked, unmasked) = (fixed(Some(mask.clone())), fixed(None));
    assert!(
        masked < 1.1 * unmasked,
        "{masked} against {unmasked} unmasked, {rounds} rounds each"
    );
}

#[test]
fn a_soft_edge_moves_the_band_less_than_the_inside() {
    let (_, noisy, mask) = noisy_bunny_and_left_half();
    let topology = Topology::build(&noisy);
    let soft = mask.with_falloff(&topology, 3);
    let mut faired = noisy.clone();
    let options = FairOptions::default()
        .with_rounds(2)
        .with_mask(Some(soft.clone()));
    fair_constrained(&mut faired, &topology, &options);
    check_only_painted_moved(&noisy, &faired.positions, &soft);
    let mean_move = |keep: &dyn Fn(f32) -> bool| {
        let moves: Vec<f64> = (0..noisy.positions.len())
            .filter(|&v| keep(soft.weight(v)))
            .map(|v| squared_distance(faired.positions[v], noisy.positions[v]).sqrt())
            .collect();
        moves.iter().sum::<f64>() / moves.len() as f64
    };
    let band = mean_move(&|w| w > 0.0 && w <= 0.25);
    let inside = mean_move(&|w| w == 1.0);
    assert!(band < 0.6 * inside, "band {band} inside {inside}");
}

/// Sum over the painted vertices of their squared distance to the surface of `clean`.
fn painted_squared_distances(clean: &TriMesh, positions: &[[f32; 3]], mask: &Mask) -> f64 {
    let surface = fairmesh::metrics::ClosestPointIndex::new(clean);
    (0..positions.len())
        .filter(|&v| mask.weight(v) > 0.0)
        .map(|v| {
            surface
                .distance(glam::DVec3::from(positions[v].map(f64::from)))
                .powi(2)
        })
        .sum()
}

#[test]
fn multires_moves_only_the_painted_region_and_removes_its_noise() {
    let (clean, noisy, mask) = noisy_bunny_and_left_half();
    let hierarchy = build_hierarchy(&noisy, &HierarchyOptions::default(), &mut NoProgress).unwrap();
    let options = MultiresOptions::default()
        .with_start_level(6)
        .with_mask(Some(mask.clone()));
    let mut workspace = MultiresWorkspace::default();
    let positions = fair_multires(&hierarchy, &options, &mut workspace, &mut NoProgress).unwrap();
    check_only_painted_moved(hierarchy.base_mesh(), &positions, &mask);
    // The painted half came much closer to the clean bunny's surface: its squared distances
    // summed fall to 22 % of the input's (measured).
    let before = painted_squared_distances(&clean, &noisy.positions, &mask);
    let after = painted_squared_distances(&clean, &positions, &mask);
    assert!(after < 0.3 * before, "{after} against {before}");
}

#[test]
fn baselines_are_blended_back_outside_the_mask() {
    let (_, noisy, mask) = noisy_bunny_and_left_half();
    let topology = Topology::build(&noisy);
    let mut faired = noisy.clone();
    let options = MethodOptions::Laplacian(LaplacianOptions::default());
    fair_masked(&mut faired, &topology, &options, &mask);
    check_only_painted_moved(&noisy, &faired.positions, &mask);
}

#[test]
fn a_mask_that_does_not_fit_leaves_the_mesh_unchanged() {
    let (_, noisy, _) = noisy_bunny_and_left_half();
    let topology = Topology::build(&noisy);
    let short = Mask::from_vertices(10, 0..10);
    assert!(short.check_fits(noisy.positions.len()).is_err());
    let mut faired = noisy.clone();
    let options = FairOptions::default().with_mask(Some(short.clone()));
    fair_constrained(&mut faired, &topology, &options);
    assert_eq!(faired.positions, noisy.positions);
    let options = MethodOptions::Laplacian(LaplacianOptions::default());
    fair_masked(&mut faired, &topology, &options, &short);
    assert_eq!(faired.positions, noisy.positions);
}
