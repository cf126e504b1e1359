//! Headless tests of the side panel's input: a quick tap on a slider's rail (press and release
//! in one frame, as a touchpad sends it) sets the value under it and gives the slider keyboard
//! focus, so the arrow keys step it next; in the default 1280×800 window the panel's scroll bar
//! is always drawn, scrolling brings the Numbers and "Paint where to fair" on screen, and
//! folding the sections above them does too.

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

mod editor_common;
use editor_common::{bunny, harness_sized, settle};
use fairmesh_editor::app::panels::PAINT_SECTION;
use fairmesh_editor::app::App;

type Harness = egui_kittest::Harness<'static, App>;

const WINDOW: egui::Vec2 = egui::vec2(1280.0, 800.0);

fn bunny_1280x800() -> Harness {
    let mut harness = harness_sized(bunny(), WINDOW);
    settle(&mut harness);
    harness
}

/// The Start level slider's rail (the slider node, not its number field).
fn start_level_rail(harness: &Harness) -> egui::Rect {
    harness
        .get_by_role_and_label(Role::Slider, "Start level")
        .rect()
}

/// A move to `pos`, a press and a release there, all in one frame (a tap on a touchpad while
/// the window draws slowly: a software renderer's frames take tens of milliseconds).
fn tap(harness: &mut Harness, pos: egui::Pos2) {
    harness.hover_at(pos);
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    harness.step();
}

#[test]
fn a_quick_tap_on_the_slider_sets_the_level_and_the_arrows_step_it() {
    let mut harness = bunny_1280x800();
    let top = harness.state().status().level_count - 1;
    // From a middle level (a file opens at 0), so that a tap near either end moves it far.
    assert_eq!(harness.state().status().level, 0);
    harness
        .state_mut()
        .push_command(fairmesh_editor::app::Command::SetLevel(top / 2));
    settle(&mut harness);
    let level = harness.state().status().level;
    assert!(
        level > 1 && level < top - 1,
        "a middle level: {level} of {top}"
    );
    let rail = start_level_rail(&harness);
    // Near the left end of the rail: level 0 or 1, far from where it was.
    tap(&mut harness, egui::pos2(rail.left() + 9.0, rail.center().y));
    settle(&mut harness);
    let tapped = harness.state().status().level;
    assert!(tapped <= 1, "the tap set the level under it: {tapped}");
    let slider = harness.get_by_role_and_label(Role::Slider, "Start level");
    assert!(
        slider.is_focused(),
        "the tap gave the slider keyboard focus"
    );

    harness.key_press(egui::Key::ArrowRight);
    harness.step();
    settle(&mut harness);
    assert_eq!(
        harness.state().status().level,
        tapped + 1,
        "the arrow stepped it"
    );

    // Near the right end: the top level.
    let rail = start_level_rail(&harness);
    tap(
        &mut harness,
        egui::pos2(rail.right() - 9.0, rail.center().y),
    );
    settle(&mut harness);
    assert_eq!(harness.state().status().level, top);
}

/// The heading `title` (the topmost node of that name: "Export" is a button below its heading).
fn heading<'a>(harness: &'a Harness, title: &'a str) -> egui_kittest::Node<'a> {
    harness
        .query_all_by_label(title)
        .min_by(|a, b| a.rect().top().total_cmp(&b.rect().top()))
        .expect("the heading")
}

/// The top of the heading `title`, in points.
fn heading_top(harness: &Harness, title: &str) -> f32 {
    heading(harness, title).rect().top()
}

#[test]
fn numbers_and_paint_are_reachable_in_a_1280x800_window() {
    let mut harness = bunny_1280x800();
    let numbers = heading_top(&harness, "Numbers");
    assert!(numbers > WINDOW.y, "below the fold at first: {numbers}");
    // The scroll bar is drawn without the pointer over the panel: a bright bar in the panel's
    // last pixel columns, beside the side panel's first rows.
    harness.remove_cursor();
    harness.step();
    let image = harness.render().unwrap();
    let scale = image.width() as f32 / WINDOW.x;
    // The handle: a column of mid-grey pixels among the panel's last 20 points (the panel is a
    // darker grey, its text is lighter and not a long column).
    let bar = (((WINDOW.x - 20.0) * scale) as u32..image.width())
        .map(|x| {
            (0..image.height())
                .filter(|&y| {
                    let p = image.get_pixel(x, y);
                    (45..=120).contains(&p[0]) && p[0] == p[1] && p[1] == p[2]
                })
                .count()
        })
        .max()
        .unwrap_or(0);
    assert!(
        bar as f32 > 50.0 * scale,
        "the scroll bar is drawn ({bar} px)"
    );

    // The wheel over the panel scrolls it: the Numbers and Paint come into the window.
    let over_panel = egui::pos2(WINDOW.x - 150.0, 400.0);
    harness.hover_at(over_panel);
    for _ in 0..30 {
        harness.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -80.0),
            modifiers: egui::Modifiers::NONE,
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Wheel,
        });
        harness.step();
    }
    harness.step();
    let paint = heading_top(&harness, PAINT_SECTION);
    assert!(
        paint > 0.0 && paint < WINDOW.y - 40.0,
        "Paint on screen: {paint}"
    );
    harness.get_by_label("Clear mask");

    // Without scrolling: folding the sections above brings the Numbers and Paint up.
    let mut harness = bunny_1280x800();
    for title in ["Noise", "Hierarchy", "Export"] {
        heading(&harness, title).click();
        harness.step();
    }
    harness.step();
    assert!(
        harness.query_by_label("Add noise").is_none(),
        "Noise is folded"
    );
    let numbers = heading_top(&harness, "Numbers");
    assert!(numbers < WINDOW.y - 200.0, "Numbers on screen: {numbers}");
    heading(&harness, "Numbers").click();
    harness.step();
    harness.step();
    let paint = heading_top(&harness, PAINT_SECTION);
    assert!(paint < WINDOW.y - 200.0, "Paint on screen: {paint}");
    harness.get_by_label("Clear mask");
    // Unfolded again, it is all back.
    heading(&harness, "Noise").click();
    harness.step();
    harness.get_by_label("Add noise");
}

/// While the hierarchy is built again (another sharp-edge setting), the Start level slider
/// still shows the level picked, not 0.
#[test]
fn the_start_level_keeps_its_value_while_the_hierarchy_rebuilds() {
    use egui_kittest::kittest::NodeT as _;
    let mut harness = bunny_1280x800();
    let level = editor_common::at_middle_level(&mut harness);
    assert!(level > 0);
    harness.get_by_label("Keep sharp edges").click();
    harness.step();
    harness.step();
    assert!(
        !harness.state().status().hierarchy_ready,
        "the hierarchy is being built again"
    );
    let shown = harness
        .get_by_role_and_label(Role::Slider, "Start level")
        .accesskit_node()
        .numeric_value();
    assert_eq!(shown, Some(level as f64));
    settle(&mut harness);
    assert_eq!(harness.state().status().level, level);
}
