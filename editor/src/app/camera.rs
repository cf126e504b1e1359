//! Orbit camera for the viewport: turns around a target point (left drag), pans in the view
//! plane (right or middle drag), zooms by changing the distance (scroll), and fits a bounding box.
//! Y is up, as in the bundled bunny and most scan formats.

use glam::{Mat4, Vec3, Vec4};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub distance: f32,
    /// Rotation about the up axis, radians.
    pub yaw: f32,
    /// Elevation above the horizontal plane, radians, within about +-89 degrees.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Radius of the scene's bounding sphere, for the clip planes and pan/zoom speeds.
    pub scene_radius: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            distance: 3.0,
            yaw: 0.0,
            pitch: 0.15,
            fov_y: 35f32.to_radians(),
            scene_radius: 1.0,
        }
    }
}

impl OrbitCamera {
    const PITCH_LIMIT: f32 = 1.55;

    /// Unit vector from the target towards the eye.
    fn backward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(sy * cp, sp, cy * cp)
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.backward() * self.distance
    }

    /// Camera right and up vectors in world space.
    pub fn basis(&self) -> (Vec3, Vec3) {
        let back = self.backward();
        let right = Vec3::Y.cross(back).normalize_or(Vec3::X);
        let up = back.cross(right);
        (right, up)
    }

    /// Frames an axis-aligned box (min, max) from the current direction in a view `aspect`
    /// wide per unit height: the box's bounding sphere fits both the height and the width (a
    /// side-by-side half is narrower than tall).
    pub fn fit(&mut self, min: Vec3, max: Vec3, aspect: f32) {
        if !(min.is_finite() && max.is_finite()) {
            return;
        }
        self.target = (min + max) * 0.5;
        self.scene_radius = ((max - min).length() * 0.5).max(1e-6);
        let half_fov_x = ((self.fov_y * 0.5).tan() * aspect.clamp(1e-3, 1e3)).atan();
        let half_fov = (self.fov_y * 0.5).min(half_fov_x);
        self.distance = self.scene_radius / half_fov.sin() * 1.05;
    }

    /// Rotates by a mouse drag of `delta` points.
    pub fn orbit(&mut self, delta: egui::Vec2) {
        self.yaw -= delta.x * 0.008;
        self.pitch = (self.pitch + delta.y * 0.008).clamp(-Self::PITCH_LIMIT, Self::PITCH_LIMIT);
    }

    /// Moves the target so that the point under the cursor follows a drag of `delta` points in
    /// a viewport `viewport_height` points tall.
    pub fn pan(&mut self, delta: egui::Vec2, viewport_height: f32) {
        let (right, up) = self.basis();
        let units_per_point =
            2.0 * self.distance * (self.fov_y * 0.5).tan() / viewport_height.max(1.0);
        self.target += (-right * delta.x + up * delta.y) * units_per_point;
    }

    /// Zooms by a scroll of `scroll` points (positive: closer).
    pub fn zoom(&mut self, scroll: f32) {
        let factor = (-scroll * 0.002).exp();
        self.distance =
            (self.distance * factor).clamp(self.scene_radius * 1e-3, self.scene_radius * 1e3);
    }

    /// Projection times view for an image `aspect` wide per unit height (depth range 0..1).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let eye = self.eye();
        let (_, up) = self.basis();
        let view = look_at(eye, self.target, up);
        let far = self.distance + self.scene_radius * 2.0;
        let near = (self.distance - self.scene_radius * 2.0).max(far * 1e-4);
        perspective(self.fov_y, aspect.max(1e-3), near, far) * view
    }

    /// Key light direction (towards the light): above and to the left of the viewer.
    pub fn light_dir(&self) -> Vec3 {
        let (right, up) = self.basis();
        (self.backward() + up * 0.6 - right * 0.4).normalize()
    }

    /// The studio lighting's fill light (towards it): right of the viewer, a little low.
    pub fn fill_dir(&self) -> Vec3 {
        let (right, up) = self.basis();
        (self.backward() * 0.6 + right * 0.8 - up * 0.2).normalize()
    }
}

/// Right-handed view matrix: the camera at `eye` looks at `target`, `up` roughly up.
fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let forward = (target - eye).normalize_or(Vec3::NEG_Z);
    let side = forward.cross(up).normalize_or(Vec3::X);
    let up = side.cross(forward);
    Mat4::from_cols(
        Vec4::new(side.x, up.x, -forward.x, 0.0),
        Vec4::new(side.y, up.y, -forward.y, 0.0),
        Vec4::new(side.z, up.z, -forward.z, 0.0),
        Vec4::new(-side.dot(eye), -up.dot(eye), forward.dot(eye), 1.0),
    )
}

/// Right-handed perspective projection onto wgpu's clip space (depth 0 at `near`, 1 at `far`).
fn perspective(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let h = 1.0 / (fov_y * 0.5).tan();
    let depth = far / (near - far);
    Mat4::from_cols(
        Vec4::new(h / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, h, 0.0, 0.0),
        Vec4::new(0.0, 0.0, depth, -1.0),
        Vec4::new(0.0, 0.0, depth * near, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_puts_box_centre_in_view_centre() {
        let mut camera = OrbitCamera::default();
        camera.fit(Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 4.0, 2.0), 1.0);
        let centre = camera
            .view_proj(1.0)
            .project_point3(Vec3::new(0.0, 3.0, 1.0));
        assert!(centre.x.abs() < 1e-4 && centre.y.abs() < 1e-4);
        assert!(centre.z > 0.0 && centre.z < 1.0);
        // Every corner is inside the clip volume.
        for corner in [Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 4.0, 2.0)] {
            let p = camera.view_proj(1.0).project_point3(corner);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && p.z > 0.0 && p.z < 1.0);
        }
    }

    #[test]
    fn fit_in_a_narrow_view_keeps_the_box_inside_its_width() {
        let (min, max) = (Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0));
        for aspect in [0.4, 1.0, 2.5] {
            let mut camera = OrbitCamera::default();
            camera.fit(min, max, aspect);
            for x in [-1.0, 1.0] {
                for y in [-1.0, 1.0] {
                    for z in [-1.0, 1.0] {
                        let p = camera.view_proj(aspect).project_point3(Vec3::new(x, y, z));
                        assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{aspect}: {p}");
                    }
                }
            }
        }
    }

    #[test]
    fn orbit_keeps_distance_and_clamps_pitch() {
        let mut camera = OrbitCamera::default();
        let before = (camera.eye() - camera.target).length();
        camera.orbit(egui::vec2(130.0, 10_000.0));
        assert!((camera.pitch - OrbitCamera::PITCH_LIMIT).abs() < 1e-6);
        assert!(((camera.eye() - camera.target).length() - before).abs() < 1e-4);
    }

    #[test]
    fn zoom_in_gets_closer() {
        let mut camera = OrbitCamera::default();
        let before = camera.distance;
        camera.zoom(100.0);
        assert!(camera.distance < before);
    }
}
