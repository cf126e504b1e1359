//! Keyboard shortcuts and dropped files, turned into commands (or display toggles).

use std::path::PathBuf;

use crate::app::{App, Command};

impl App {
    pub(super) fn handle_global_input(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            self.commands.push(Command::Open(path));
        }
        // Shortcuts work unless a text field has the keyboard (it has its own undo, and typing
        // an F or a W must not fit the view or toggle the wireframe).
        let text_focus = ctx.text_edit_focused();
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
        if text_focus {
            return;
        }
        let plain = |i: &egui::InputState, key| i.key_pressed(key) && i.modifiers.is_none();
        let (fit, wire, before, heat, paint) = ctx.input(|i| {
            (
                plain(i, egui::Key::F),
                plain(i, egui::Key::W),
                plain(i, egui::Key::B),
                plain(i, egui::Key::H),
                plain(i, egui::Key::P),
            )
        });
        if paint {
            self.paint_mode = !self.paint_mode;
            if !self.paint_mode {
                self.commands.push(Command::EndStroke);
            }
        }
        if fit {
            self.commands.push(Command::FitView);
        }
        if wire {
            self.settings.wireframe = !self.settings.wireframe;
        }
        if before {
            self.show_before = !self.show_before;
        }
        if heat {
            self.settings.heat_map = !self.settings.heat_map;
        }
    }
}
