//! The mesh renderer's background uploads, driven directly on a software wgpu device (lavapipe or
//! llvmpipe, as in the editor tests): the newest mesh wins over uploads still in flight, and an
//! upload that panics inside the upload thread leaves a notice and a working renderer, not a
//! mesh that never arrives; the vertex normals smooth shading is drawn with are the ones of the
//! positions on screen, whether computed in the frame or on the upload thread, and a move that
//! makes an edge sharp splits them there.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_wgpu::wgpu;
use fairmesh_editor::render::normals::vertex_normals;
use fairmesh_editor::render::{MeshRenderer, MeshSource};

/// A grid of `n` × `n` quads (two triangles each) in the z = 0 plane.
struct Grid {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    /// `triangles()` panics on this call (counting from 1), if set.
    panic_on_call: Option<usize>,
    calls: AtomicUsize,
}

impl Grid {
    fn new(n: u32) -> Self {
        let positions = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| [x as f32, y as f32, 0.0]))
            .collect();
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let triangles = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [
                        [index(x, y), index(x + 1, y), index(x + 1, y + 1)],
                        [index(x, y), index(x + 1, y + 1), index(x, y + 1)],
                    ]
                })
            })
            .collect();
        Self {
            positions,
            triangles,
            panic_on_call: None,
            calls: AtomicUsize::new(0),
        }
    }
}

impl MeshSource for Grid {
    fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }
    fn triangles(&self) -> &[[u32; 3]] {
        let call = self.calls.fetch_add(1, Ordering::SeqCst) + 1;
        if self.panic_on_call == Some(call) {
            panic!("a failing upload (test)");
        }
        &self.triangles
    }
}

impl Grid {
    /// The grid bent into a dome (z falls off with the distance from the centre): its vertex
    /// normals lean outwards, unlike the flat grid's.
    fn dome(n: u32) -> Self {
        let mut grid = Self::new(n);
        let centre = n as f32 / 2.0;
        for p in &mut grid.positions {
            let (dx, dy) = (p[0] - centre, p[1] - centre);
            p[2] = -(dx * dx + dy * dy) / n as f32;
        }
        grid
    }
}

impl Grid {
    /// The grid folded up by 90° along its middle column: the half beyond it stands upright.
    fn folded(n: u32) -> Self {
        let mut grid = Self::new(n);
        let middle = (n / 2) as f32;
        for p in &mut grid.positions {
            if p[0] > middle {
                *p = [middle, p[1], p[0] - middle];
            }
        }
        grid
    }
}

impl Grid {
    /// The dome, then a flat grid behind it (z = -40, further from the test camera than any of
    /// the dome): the flat grid's faces come later and must lose the depth test.
    fn dome_over_plane(n: u32) -> Self {
        let mut dome = Self::dome(n);
        let plane = Self::new(n);
        let offset = dome.positions.len() as u32;
        dome.positions
            .extend(plane.positions.iter().map(|p| [p[0], p[1], -40.0]));
        dome.triangles
            .extend(plane.triangles.iter().map(|t| t.map(|v| v + offset)));
        dome
    }
}

fn device() -> (wgpu::Device, wgpu::Queue) {
    let state = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        Default::default(),
    );
    (state.device.clone(), state.queue.clone())
}

/// Polls until no upload is in flight (they take milliseconds here).
fn wait_for_uploads(renderer: &mut MeshRenderer, queue: &wgpu::Queue) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while renderer.upload_pending(queue) {
        assert!(Instant::now() < deadline, "an upload never landed");
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn the_newest_mesh_wins_over_uploads_in_flight() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    renderer.set_async_upload_bytes(0);
    let sizes = [120, 80, 7];
    for n in sizes {
        renderer.set_mesh(&device, Arc::new(Grid::new(n)));
    }
    wait_for_uploads(&mut renderer, &queue);
    assert!(renderer.has_mesh());
    // The mesh on screen is the last one: only its vertex count takes new positions.
    let last = (sizes[2] as usize + 1).pow(2);
    let first = (sizes[0] as usize + 1).pow(2);
    assert!(!renderer.set_positions(&queue, Arc::new(Grid::new(sizes[0]))));
    assert!(first != last);
    assert!(renderer.set_positions(&queue, Arc::new(Grid::new(sizes[2]))));

    // A big mesh goes to the upload thread, then a small one is uploaded in the frame: the big
    // one lands later and must not replace it.
    renderer.set_mesh(&device, Arc::new(Grid::new(150)));
    renderer.set_async_upload_bytes(usize::MAX);
    renderer.set_mesh(&device, Arc::new(Grid::new(5)));
    std::thread::sleep(Duration::from_millis(300));
    wait_for_uploads(&mut renderer, &queue);
    assert!(renderer.set_positions(&queue, Arc::new(Grid::new(5))));
}

#[test]
fn a_failed_upload_leaves_a_notice_and_a_working_renderer() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    renderer.set_async_upload_bytes(0);
    // Call 1 is `set_mesh` counting faces on this thread; call 2 is on the upload thread.
    let mut failing = Grid::new(20);
    failing.panic_on_call = Some(2);
    renderer.set_mesh(&device, Arc::new(failing));
    wait_for_uploads(&mut renderer, &queue);
    assert!(!renderer.has_mesh());
    assert_eq!(
        renderer.problem(false).as_deref(),
        Some("the GPU could not take the mesh's buffers")
    );
    // The upload thread survived: the next mesh arrives, and the notice goes.
    renderer.set_mesh(&device, Arc::new(Grid::new(20)));
    wait_for_uploads(&mut renderer, &queue);
    assert!(renderer.has_mesh());
    assert_eq!(renderer.problem(false), None);
    assert!(renderer.set_positions(&queue, Arc::new(Grid::new(20))));
}

/// The normals in the GPU buffer: the flat grid's point straight up; after a move to the dome
/// they are the dome's area-weighted normals (not the flat ones, and not face normals), both
/// when computed in the frame and on the upload thread, where the move waits for them.
#[test]
fn uploaded_normals_follow_the_positions_on_screen() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    let n = 12;
    let count = ((n + 1) * (n + 1)) as usize;
    for async_bytes in [usize::MAX, 0] {
        renderer.set_async_upload_bytes(async_bytes);
        renderer.set_mesh(&device, Arc::new(Grid::new(n)));
        wait_for_uploads(&mut renderer, &queue);
        let flat = renderer
            .read_back_normals(&device, &queue)
            .expect("normals");
        assert_eq!(flat.len(), count);
        assert!(flat.iter().all(|n| *n == [0.0, 0.0, 1.0]), "{:?}", flat[0]);

        let dome = Grid::dome(n);
        let expected = vertex_normals(&dome.positions, &dome.triangles);
        assert!(renderer.set_positions(&queue, Arc::new(dome)));
        wait_for_uploads(&mut renderer, &queue);
        let moved = renderer
            .read_back_normals(&device, &queue)
            .expect("normals");
        assert_eq!(moved, expected, "async upload: {}", async_bytes == 0);
        // A corner's normal leans out of the dome; the centre's stays up.
        assert!(moved[0][2] < 0.95 && moved[0][0] < 0.0 && moved[0][1] < 0.0);
        let centre = (n / 2 * (n + 1) + n / 2) as usize;
        assert!(moved[centre][2] > 0.999);
    }
}

/// A move that folds the flat grid sharply splits the shading at the fold: each side is lit with
/// its own normal up to the fold, so the mesh gets buffers with one more draw vertex per fold
/// vertex, in the frame and on the upload thread; unfolded again, it is drawn over its own
/// vertices with their normals, as before. It stays the same mesh throughout (moves, not new
/// meshes), and takes heat-map values per mesh vertex as ever.
#[test]
fn a_move_that_folds_the_mesh_splits_its_shading_at_the_fold() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    let n = 8;
    let count = ((n + 1) * (n + 1)) as usize;
    for async_bytes in [usize::MAX, 0] {
        renderer.set_async_upload_bytes(async_bytes);
        renderer.set_mesh(&device, Arc::new(Grid::new(n)));
        wait_for_uploads(&mut renderer, &queue);
        let meshes = renderer.uploads.meshes;
        let folded = Grid::folded(n);
        assert!(renderer.set_positions(&queue, Arc::new(Grid::folded(n))));
        assert!(renderer.set_scalars(&queue, &vec![0.5; count]));
        wait_for_uploads(&mut renderer, &queue);
        let normals = renderer.read_back_normals(&device, &queue).unwrap();
        assert_eq!(normals.len(), count + (n + 1) as usize);
        let corners = renderer.read_back_corner_normals(&device, &queue).unwrap();
        assert_eq!(corners.len(), folded.triangles.len());
        for (drawn, t) in corners.iter().zip(&folded.triangles) {
            assert_eq!(drawn.vertices, *t);
            let [a, b, c] = t.map(|v| glam::Vec3::from_array(folded.positions[v as usize]));
            let face = (b - a).cross(c - a).normalize();
            for normal in drawn.normals {
                let off = (glam::Vec3::from_array(normal) - face).length();
                assert!(off < 1e-5, "{t:?}: {normal:?} against {face}");
            }
        }
        assert!(renderer.set_positions(&queue, Arc::new(Grid::new(n))));
        wait_for_uploads(&mut renderer, &queue);
        let flat = renderer.read_back_normals(&device, &queue).unwrap();
        assert_eq!(flat.len(), count);
        assert!(flat.iter().all(|n| *n == [0.0, 0.0, 1.0]));
        assert_eq!(
            renderer.uploads.meshes,
            meshes,
            "async: {}",
            async_bytes == 0
        );
        assert!(renderer.set_scalars(&queue, &vec![0.5; count]));
    }
}

/// A camera looking down at the grids (x and y from 0 to 200 fill the view), scaled by `zoom`.
fn params(size: [u32; 2], zoom: f32, wireframe: bool) -> fairmesh_editor::render::DrawParams {
    let s = 0.01 * zoom;
    fairmesh_editor::render::DrawParams {
        view_proj: [
            [s, 0.0, 0.0, 0.0],
            [0.0, s, 0.0, 0.0],
            [0.0, 0.0, -0.01, 0.0],
            [-1.0, -1.0, 0.5, 1.0],
        ],
        eye: [100.0, 100.0, 100.0],
        light_dir: [0.0, 0.0, 1.0],
        fill_dir: [1.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        shading: Default::default(),
        lighting: Default::default(),
        wireframe,
        scalar_range: None,
        mask_tint: false,
        clay: false,
        size,
    }
}

/// Draws what is on screen into a target of `size`, checking that wgpu reports no error.
fn draw(renderer: &mut MeshRenderer, device: &wgpu::Device, queue: &wgpu::Queue, size: [u32; 2]) {
    renderer.ensure_target(device, size);
    assert!(render_once(
        renderer,
        device,
        queue,
        &params(size, 1.0, false)
    ));
}

/// One frame's `render` with `params`, submitted; checks that wgpu reports no error.
fn render_once(
    renderer: &mut MeshRenderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    params: &fairmesh_editor::render::DrawParams,
) -> bool {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut encoder = device.create_command_encoder(&Default::default());
    let drew = renderer.render(device, queue, &mut encoder, params);
    queue.submit([encoder.finish()]);
    let error = pollster::block_on(scope.pop());
    assert!(error.is_none(), "{error:?}");
    drew
}

#[test]
fn an_image_drawn_over_several_frames_is_the_image_drawn_at_once() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    renderer.set_async_upload_bytes(usize::MAX);
    // A dome over a plane, 2 × 2 × 40² = 6400 faces (and 19200 wireframe edges), into a 4×
    // multisampled target: the plane's faces, drawn in later parts, are hidden by the depth the
    // dome's left.
    renderer.set_mesh(&device, Arc::new(Grid::dome_over_plane(40)));
    let size = [96, 80];
    renderer.ensure_target(&device, size);
    let near = params(size, 3.0, true);
    let far = params(size, 1.0, true);
    // At once: the reference images of both views.
    assert!(render_once(&mut renderer, &device, &queue, &near));
    let near_image = renderer.read_back_image(&device, &queue).unwrap();
    assert!(render_once(&mut renderer, &device, &queue, &far));
    let far_image = renderer.read_back_image(&device, &queue).unwrap();
    assert_ne!(near_image, far_image);

    // In parts of 1000 faces or edges: 6400 + 19200 take 26 frames; meanwhile the target keeps
    // the previous image and no image counts as drawn.
    renderer.set_faces_per_frame(1000);
    let drawn_before = renderer.image_counts().drawn;
    for frame in 0..26 {
        assert!(
            render_once(&mut renderer, &device, &queue, &near),
            "frame {frame}"
        );
        if frame < 25 {
            assert!(renderer.drawing(), "frame {frame}");
            assert_eq!(renderer.image_counts().drawn, drawn_before);
            // Set once the first part was drawn: which image is shown must not change meanwhile.
            if frame % 9 == 0 {
                let shown = renderer.read_back_image(&device, &queue).unwrap();
                assert!(shown == far_image, "frame {frame} shows a part-drawn image");
            }
        }
    }
    assert!(!renderer.drawing());
    assert_eq!(renderer.image_counts().drawn, drawn_before + 1);
    assert!(renderer.read_back_image(&device, &queue).unwrap() == near_image);
    assert!(
        !render_once(&mut renderer, &device, &queue, &near),
        "nothing new to draw"
    );

    // An image in progress is finished with its own view before a newer view begins.
    assert!(render_once(&mut renderer, &device, &queue, &far));
    for _ in 1..26 {
        assert!(render_once(&mut renderer, &device, &queue, &near));
    }
    assert!(!renderer.drawing());
    assert!(renderer.read_back_image(&device, &queue).unwrap() == far_image);

    // New positions drop a half-drawn image: the next one starts over with them.
    assert!(render_once(&mut renderer, &device, &queue, &near));
    assert!(renderer.drawing());
    assert!(renderer.set_positions(&queue, Arc::new(Grid::dome_over_plane(40))));
    assert!(!renderer.drawing());

    // A resized target has no image to show meanwhile: its first image is drawn at once.
    let smaller = [80, 64];
    renderer.ensure_target(&device, smaller);
    let drawn_before = renderer.image_counts().drawn;
    assert!(render_once(
        &mut renderer,
        &device,
        &queue,
        &params(smaller, 3.0, true)
    ));
    assert!(!renderer.drawing());
    assert_eq!(renderer.image_counts().drawn, drawn_before + 1);
    assert!(render_once(
        &mut renderer,
        &device,
        &queue,
        &params(smaller, 1.0, true)
    ));
    assert!(renderer.drawing(), "the next one is drawn in parts again");
}

#[test]
fn a_software_renderer_draws_big_meshes_with_one_sample_and_small_ones_with_four() {
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    renderer.set_async_upload_bytes(0);
    renderer.set_software_adapter(true);
    // 460² quads: 423k faces, over the threshold.
    let big = 460;
    assert!(2 * big * big > fairmesh_editor::render::SOFTWARE_SINGLE_SAMPLE_FACES as u32);
    for (n, samples) in [(20, 4), (big, 1), (20, 4)] {
        renderer.set_mesh(&device, Arc::new(Grid::new(n)));
        wait_for_uploads(&mut renderer, &queue);
        assert_eq!(renderer.samples(), samples, "{n}×{n} grid");
        draw(&mut renderer, &device, &queue, [64, 48]);
    }
    // A GPU keeps its four samples for any mesh.
    renderer.set_software_adapter(false);
    renderer.set_mesh(&device, Arc::new(Grid::new(big)));
    wait_for_uploads(&mut renderer, &queue);
    assert_eq!(renderer.samples(), 4);
    draw(&mut renderer, &device, &queue, [64, 48]);
}

/// Renders frames with `params` until the image in progress is complete.
fn finish_image(
    renderer: &mut MeshRenderer,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    params: &fairmesh_editor::render::DrawParams,
) {
    render_once(renderer, device, queue, params);
    for _ in 0..1000 {
        if !renderer.drawing() {
            return;
        }
        render_once(renderer, device, queue, params);
    }
    panic!("the image was never completed");
}

#[test]
fn a_held_mesh_shows_its_kept_image_again_only_while_nothing_changed() {
    use fairmesh_editor::render::{ImageCounts, MeshKey};
    let (device, queue) = device();
    let mut renderer = MeshRenderer::new(&device, &queue, Arc::new(|| {}));
    renderer.set_async_upload_bytes(usize::MAX);
    let size = [96, 80];
    renderer.ensure_target(&device, size);
    let view = params(size, 1.0, false);
    let (dome, plane) = (
        MeshKey {
            family: 1,
            version: 0,
        },
        MeshKey {
            family: 2,
            version: 0,
        },
    );
    // Images take several frames (6400 faces in parts of 1000), but for the target's first.
    renderer.set_faces_per_frame(1000);
    renderer.set_mesh_keyed(&device, Arc::new(Grid::dome_over_plane(40)), Some(dome));
    finish_image(&mut renderer, &device, &queue, &view);
    let dome_image = renderer.read_back_image(&device, &queue).unwrap();
    renderer.set_mesh_keyed(&device, Arc::new(Grid::new(40)), Some(plane));
    finish_image(&mut renderer, &device, &queue, &view);
    let plane_image = renderer.read_back_image(&device, &queue).unwrap();
    assert_ne!(dome_image, plane_image);

    // Each comes back in one frame, nothing drawn.
    let counts = renderer.image_counts();
    assert!(renderer.show_held(&queue, dome));
    assert!(render_once(&mut renderer, &device, &queue, &view));
    assert!(!renderer.drawing());
    assert!(renderer.read_back_image(&device, &queue).unwrap() == dome_image);
    assert!(renderer.show_held(&queue, plane));
    assert!(render_once(&mut renderer, &device, &queue, &view));
    assert!(renderer.read_back_image(&device, &queue).unwrap() == plane_image);
    let restored_twice = ImageCounts {
        restored: counts.restored + 2,
        ..counts
    };
    assert_eq!(renderer.image_counts(), restored_twice);
    assert_eq!(
        renderer.image_bytes(),
        2 * 96 * 80 * 4,
        "one image per mesh"
    );

    // There and back before a frame: the target still shows the plane, nothing to do.
    assert!(renderer.show_held(&queue, dome));
    assert!(renderer.show_held(&queue, plane));
    assert!(!render_once(&mut renderer, &device, &queue, &view));
    assert!(renderer.read_back_image(&device, &queue).unwrap() == plane_image);

    // Another view: drawn, not the kept image.
    let closer = params(size, 2.0, false);
    assert!(renderer.show_held(&queue, dome));
    render_once(&mut renderer, &device, &queue, &closer);
    assert!(renderer.drawing(), "a new view is drawn in parts");
    finish_image(&mut renderer, &device, &queue, &closer);
    assert_eq!(renderer.image_counts().restored, restored_twice.restored);
    assert!(renderer.read_back_image(&device, &queue).unwrap() != dome_image);

    // Its buffers change (the heat map's scalars) and it leaves before its next image: its
    // kept image is not shown again.
    assert!(renderer.show_held(&queue, plane));
    finish_image(&mut renderer, &device, &queue, &view);
    assert!(renderer.set_scalars(&queue, &vec![0.5; 41 * 41]));
    assert!(renderer.show_held(&queue, dome));
    finish_image(&mut renderer, &device, &queue, &view);
    let restored = renderer.image_counts().restored;
    assert!(renderer.show_held(&queue, plane));
    render_once(&mut renderer, &device, &queue, &view);
    assert!(renderer.drawing(), "drawn again after its scalars changed");
    assert_eq!(renderer.image_counts().restored, restored);

    // An image goes with its mesh.
    finish_image(&mut renderer, &device, &queue, &view);
    renderer.retain_held(|key| key == plane);
    assert_eq!(renderer.image_bytes(), 96 * 80 * 4);
    assert_eq!(renderer.meshes_held(), 1);
}
