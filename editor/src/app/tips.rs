//! The side panel's tooltips: what each control does and when to change it, in plain words (tests
//! look controls up by them). The View section's are in `view_panel.rs`.

pub const NOISE_SIGMA: &str = "How strong the noise is: how far, on average, each vertex \
    is pushed, in mean edge lengths. 0.3 looks like a rough scan; 1 and more hides the shape.";
pub const NOISE_SEED: &str = "Which random pattern the noise uses. The same seed and \
    strength give the same noise again, to compare smoothers on it; change it for another.";
pub const NOISE_DIRECTION: &str = "Which way the noise pushes the vertices. Along the \
    normal: in and out of the surface, like a scanner's depth error. Random direction (the \
    paper's test) and Isotropic (x, y and z each on their own): also along the surface, \
    which jitters the triangles too.";
pub const KEEP_SHARP_EDGES: &str = "Keep the mesh's sharp edges (the edges of a machined \
    part, a fold, a rim) sharp: the coarse levels keep them and the smoothing runs along them, \
    not across them. Edges your file marks as hard (where its normals split, or two of its \
    materials meet) are kept too, however gentle the fold. Turn it off for organic shapes if \
    smoothing leaves ridges where there should be none.";
pub const SHARP_EDGE_ANGLE: &str = "How sharply the surface must fold at an edge for the edge \
    to be kept sharp. Lower: more edges are kept (gentle folds too). Higher: only the sharpest. \
    The kept edges are drawn over the mesh while you point here.";
pub const START_LEVEL: &str = "How coarse a version of the mesh the smoothing starts from. \
    0 (where a file opens): the mesh with its noise removed and all its detail kept (the \
    same result as the command line's `fair`). Moving it right takes detail away: each level \
    is coarser, so bigger bumps and fine detail go too and the result is smoother. Raise it \
    until the surface is as plain as you want; lower it if wanted features melt away.";
pub const FOLDS_LEFT: &str = "Coming back from a very coarse level to full detail, a few \
    triangles ended turned over (in flat shading they can show as dark specks). Elsewhere \
    they are undone by putting their corners back where level 0 has them, but here the smooth \
    result lies so far from level 0 that doing so would bring level 0's detail back in \
    patches with seams over much of the mesh, so they are left. A lower start level has none.";
pub const REMOVE_NOISE: &str = "Remove the mesh's noise before anything else, once: the \
    smoother measures how noisy the mesh is and smooths until the result stops getting \
    better (a clean mesh is left as it is). The levels are built on the result, so the \
    start level only takes away detail on top of it. Automatic is right for nearly every \
    mesh.";
pub const DENOISE_AUTOMATIC: &str = "Measure the noise and smooth as much as it needs: \
    the same result as the command line's `fair` with no options.";
pub const DENOISE_ROUNDS: &str = "Smooth exactly this many rounds instead of measuring the \
    noise: more rounds remove more (and round off more of the fine detail).";
pub const DENOISE_OFF: &str = "Do not remove noise first: the smoothing starts at the start \
    level alone, as in the paper (M0 then gets a few light passes).";
pub const HIERARCHY_BUILDING: &str = "First the noise is removed (see Remove noise first), \
    then the mesh is simplified level by level for the start level slider. Both happen once \
    per mesh, in the background.";
pub const CANCEL_HIERARCHY: &str = "Stop removing the noise and building the levels. \
    Build hierarchy starts them again.";
pub const METHOD: &str = "Constrained fairing (the paper's method) smooths without \
    shrinking the mesh. The others are classic smoothers to compare with: watch the volume \
    change under Numbers.";
pub const ITERATIONS_PER_LEVEL: &str = "Smoothing passes on each level on the way back to \
    full detail. More: a little smoother and slower. The start level matters far more: \
    change this last.";
pub const ROUNDS: &str = "How often each level's smoothing starts over from where it got \
    to. More: a little smoother and slower; 1 is usually enough.";
pub const BASELINE_ITERATIONS: &str = "Smoothing passes over the whole mesh. More: \
    smoother, and (for Laplacian) more shrinkage.";
pub const LAMBDA: &str = "How far each pass moves a vertex towards its neighbours (0 to \
    1). Higher: faster smoothing, more shrinkage.";
pub const BOUNDARY: &str = "What happens to open borders (holes, cut edges). Smooth as \
    curve: the border line is smoothed too. Fixed: border vertices stay where they are; use \
    it when the mesh must still meet another part.";
pub const FAIR_FINEST: &str = "Also smooth the full-detail mesh (M0) at the end, lightly. \
    On: the vertices put back from the coarse levels are evened out (a few edges would stay \
    folded otherwise). Off: they stay where they were put back.";
pub const VARIANT: &str = "Paper: the method as published. Improved: two corrections that \
    keep the shape from drifting and shrinking over the levels. Keep Improved unless you \
    compare with the paper.";
pub const PAINT: &str = "Paint where to fair (P). On: the left button paints on the mesh \
    instead of turning the view (middle drag turns it, right drag pans). Only the painted \
    part is smoothed; the rest keeps its exact shape.";
pub const BRUSH_ADD: &str = "The brush marks the part to smooth.";
pub const BRUSH_ERASE: &str = "The brush unmarks what it touches, so it keeps its shape \
    (on a mesh with no mask yet: protects it while the rest is smoothed). Hold Shift to \
    erase for a moment.";
pub const BRUSH_RADIUS: &str = "Size of the brush on screen, in points. Zoom in to paint \
    finer detail.";
pub const BRUSH_SOFTNESS: &str = "How much of the brush's edge fades out. Higher: the \
    smoothing blends gently into the untouched part; 0: a hard edge.";
pub const SHOW_MASK: &str = "Tint the painted part orange on the mesh (over the heat map, \
    only its edge is drawn, so the map's colours stay true).";
pub const CLEAR_MASK: &str = "Remove the paint: the whole mesh is smoothed again (undo \
    with Ctrl+Z).";
pub const INVERT_MASK: &str = "Smooth what was left alone and keep what was painted \
    (undo with Ctrl+Z).";
pub const APPLY: &str = "Make the result the input mesh, to add noise to it, fair it \
    again or export it as it is (undo with Ctrl+Z).";

// The Numbers section.

/// What each row of the measures grid means (its name's tooltip), in the rows' order.
pub const ROW_TIPS: [(&str, &str); 5] = [
    (
        "Volume change",
        "How much the volume the surface encloses changed, in percent. Smoothers that shrink \
         the mesh show it here; constrained fairing keeps it near 0.",
    ),
    (
        "Mean distance",
        "How far the result's surface lies from the other mesh's surface, on average over \
         the area, measured both ways. In model units.",
    ),
    (
        "Max distance",
        "The farthest any point of one surface lies from the other (the Hausdorff \
         distance): where the result changed most. In model units.",
    ),
    (
        "RMS displacement",
        "How far the vertices moved, as a root mean square over all vertices. In model units.",
    ),
    (
        "Barycenter drift",
        "How far the mesh's centre (the mean of its vertices) moved. Near 0 when the \
         smoothing does not push the mesh one way. In model units.",
    ),
];

/// Said when the result is farther from the clean mesh than the input mesh (the noise) was.
pub const FARTHER_THAN_NOISE: &str = "The result is farther from the clean mesh than the \
    noisy input is. The clean mesh is the input as it was before noise was added: if that \
    file was noisy or detailed already, the fairing smooths its own bumps too, and those \
    count as distance. Lower the start level to keep more detail.";

/// What the Noise row says.
pub const NOISE_ROW: &str = "Mean distance of the input mesh from the clean mesh: how far the \
    noise moved the surface. A good result comes back closer to clean than this.";

// The Export section.

/// The formats Export writes, as the editor guide (docs/editor.md) lists them.
pub const EXPORT_FORMATS: &str = "GLB, glTF, OBJ, PLY, STL or OFF, by extension";
/// What Export does in the web page (shown under the export path there).
pub const WEB_EXPORT: &str = "In the browser, Export downloads the file. A file that needs \
    others beside it (an OBJ with its .mtl and images, a .gltf with its .bin and images) comes \
    as one .zip; name the export .glb for a single file with everything in it. Export levels \
    downloads the level chain as one .zip of GLB files.";
pub const HELD_MESHES: &str = "The meshes the 3D view keeps on the graphics card: the one \
    shown, and those you switched away from (Faired, Level mesh, Input mesh), so that switching \
    back uploads nothing. A new result or level takes the place of the old one; the Before \
    view keeps its own copy of the input mesh.";
pub const KEPT_IMAGE: &str = "The last image drawn of each held mesh. Switching back to a \
    mesh while the view is as it was (the same camera, window size and display settings) shows \
    this image at once instead of drawing the mesh again. It takes 4 bytes a pixel of the 3D \
    view.";
pub const VIEWPORT_IMAGES: &str = "Images of the 3D view drawn so far, and how many times a \
    held mesh's kept image was shown instead of drawing the mesh again.";
pub const RESET_MAX: &str = "Forget the longest frame while working, to measure the next \
    piece of work on its own.";
