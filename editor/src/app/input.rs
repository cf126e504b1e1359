//! Keyboard shortcuts and dropped files, turned into commands (or display toggles).

use std::path::PathBuf;

use crate::app::{App, Command};
use crate::render::Shading;

impl App {
    pub(super) fn handle_global_input(&mut self, ctx: &egui::Context) {
        #[cfg(not(target_arch = "wasm32"))]
        if let Some(path) = dropped_file(ctx) {
            self.commands.push(Command::Open(path));
        }
        // A page gets the dropped files' bytes, not their paths.
        #[cfg(target_arch = "wasm32")]
        self.open_dropped_files(ctx);
        // Shortcuts work unless a text field has the keyboard (it has its own undo, and typing
        // an F or a W must not fit the view or toggle the wireframe).
        let text_focus = ctx.text_edit_focused();
        self.command_shortcuts(ctx, text_focus);
        if !text_focus {
            self.plain_key_toggles(ctx);
        }
    }

    /// The shortcuts with Ctrl (Cmd on macOS): open, export, save image, undo and redo (the
    /// last two not while a text field has the keyboard).
    fn command_shortcuts(&mut self, ctx: &egui::Context, text_focus: bool) {
        let (undo, redo) = ctx.input(|i| {
            let command = i.modifiers.command;
            (
                command && !i.modifiers.shift && i.key_pressed(egui::Key::Z),
                command
                    && ((i.modifiers.shift && i.key_pressed(egui::Key::Z))
                        || i.key_pressed(egui::Key::Y)),
            )
        });
        let (open, export) = ctx.input(|i| {
            let command_only = i.modifiers.command && !i.modifiers.shift && !i.modifiers.alt;
            (
                command_only && i.key_pressed(egui::Key::O),
                command_only && i.key_pressed(egui::Key::E),
            )
        });
        if open {
            self.commands.push(Command::OpenDialog);
        }
        let save_image = ctx.input(|i| {
            i.modifiers.command
                && i.modifiers.shift
                && !i.modifiers.alt
                && i.key_pressed(egui::Key::S)
        });
        if save_image {
            self.commands.push(Command::SaveViewImage);
        }
        if export {
            if let Some(document) = &self.document {
                let path = PathBuf::from(document.export_path.trim());
                self.commands.push(Command::Export(path));
            }
        }
        if !text_focus && undo {
            self.commands.push(Command::Undo);
        }
        if !text_focus && redo {
            self.commands.push(Command::Redo);
        }
    }

    /// The keys without modifiers: F fit view, W wireframe, B before/after, H heat map,
    /// P paint, S shading (Flat / Smooth), C clay.
    fn plain_key_toggles(&mut self, ctx: &egui::Context) {
        let plain = |i: &egui::InputState, key| i.key_pressed(key) && i.modifiers.is_none();
        let (fit, wire, before, heat, paint, shading, clay) = ctx.input(|i| {
            (
                plain(i, egui::Key::F),
                plain(i, egui::Key::W),
                plain(i, egui::Key::B),
                plain(i, egui::Key::H),
                plain(i, egui::Key::P),
                plain(i, egui::Key::S),
                plain(i, egui::Key::C),
            )
        });
        if clay {
            self.settings.view.clay = !self.settings.view.clay;
        }
        if paint {
            self.painting.paint_mode = !self.painting.paint_mode;
            if !self.painting.paint_mode {
                self.commands.push(Command::EndStroke);
            }
        }
        if fit {
            self.commands.push(Command::FitView);
        }
        if wire {
            self.settings.view.wireframe = !self.settings.view.wireframe;
        }
        if before {
            self.view.show_before = !self.view.show_before;
        }
        if heat {
            self.settings.view.heat_map = !self.settings.view.heat_map;
        }
        if shading {
            self.settings.view.shading = match self.settings.view.shading {
                Shading::Flat => Shading::Smooth,
                Shading::Smooth => Shading::Flat,
            };
        }
    }
}

/// The first file dropped on the window in this frame.
#[cfg(not(target_arch = "wasm32"))]
fn dropped_file(ctx: &egui::Context) -> Option<PathBuf> {
    let dropped: Vec<PathBuf> = ctx.input(|i| {
        i.raw
            .dropped_files
            .iter()
            .map(|f| f.path().to_path_buf())
            .filter(|p| !p.as_os_str().is_empty())
            .collect()
    });
    dropped.into_iter().next()
}
