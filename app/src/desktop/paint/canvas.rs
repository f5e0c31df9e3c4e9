//! The paint panel's canvas: the shown map over the UV square with the
//! mesh, strokes and clicks made into dabs, the brush outline and the
//! value under the pointer.

use super::*;

impl PaintState {
    /// The UV canvas: the map, the UV layout, arrows for the direction map.
    pub(super) fn canvas(
        &mut self,
        ui: &mut egui::Ui,
        project: &Project,
        template: usize,
        current: &Template,
    ) -> Vec<Command> {
        let side = ui
            .available_width()
            .min(0.6 * ui.available_height())
            .max(120.0);
        let (rect, response) = ui.allocate_exact_size(Vec2::splat(side), Sense::click_and_drag());
        response
            .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "UV paint canvas"));
        // Ctrl+wheel (egui's zoom modifier, Cmd on a Mac) zooms; the wheel
        // alone scrolls the panel, as over any other widget.
        let factor = ui.input(egui::InputState::zoom_delta);
        if factor != 1.0
            && let Some(pointer) = response.hover_pos()
        {
            // Zoom about the pointer.
            let before = (pointer - rect.min - self.pan) / self.zoom;
            self.zoom = (self.zoom * factor).clamp(0.5, 16.0);
            self.pan = pointer - rect.min - before * self.zoom;
        }
        if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            self.pan += response.drag_delta();
        }
        if response.double_clicked() {
            self.zoom = 1.0;
            self.pan = Vec2::ZERO;
        }
        let (pan, size) = (self.pan, side * self.zoom);
        let to_screen = |uv: DVec2| {
            Pos2::new(
                rect.left() + pan.x + uv.x as f32 * size,
                rect.top() + pan.y + (1.0 - uv.y as f32) * size,
            )
        };
        let to_uv = |p: Pos2| {
            DVec2::new(
                f64::from((p.x - rect.left() - pan.x) / size),
                1.0 - f64::from((p.y - rect.top() - pan.y) / size),
            )
        };

        // Strokes: from where the drag began along the pointer's path,
        // dabs spaced along each frame's segment (whatever the frame rate).
        // A click is one dab, painted once the double-click time has passed
        // without a second click: a double-click resets the view and paints
        // nothing. Alt+click, or a click with the eyedropper, picks.
        let (now, alt, press_origin) =
            ui.input(|i| (i.time, i.modifiers.alt, i.pointer.press_origin()));
        let double_click_seconds = ui.ctx().options(|o| o.input_options.max_double_click_delay);
        let picking = alt || self.eyedropper;
        let mut dabs = Vec::new();
        if response.drag_started_by(egui::PointerButton::Primary) && !picking {
            // A pending click belongs to no stroke: paint it first.
            dabs.extend(self.flush_click(project, template));
            if let Some(origin) = press_origin {
                dabs.extend(self.stroke_to(project, template, to_uv(origin)));
            }
        }
        if response.dragged_by(egui::PointerButton::Primary)
            && !picking
            && let Some(pointer) = response.interact_pointer_pos()
        {
            dabs.extend(self.stroke_to(project, template, to_uv(pointer)));
        }
        if response.clicked_by(egui::PointerButton::Primary)
            && let Some(pointer) = response.interact_pointer_pos()
        {
            if picking {
                self.pick(current, to_uv(pointer));
            } else if response.double_clicked() {
                self.pending_click = None;
            } else {
                self.pending_click = Some((to_uv(pointer), now));
            }
        }
        match self.pending_click {
            Some((_, at)) if now - at > double_click_seconds => {
                dabs.extend(self.flush_click(project, template));
            }
            Some((_, at)) => ui
                .ctx()
                .request_repaint_after(std::time::Duration::from_secs_f64(
                    (double_click_seconds - (now - at)).max(0.0) + 0.01,
                )),
            None => {}
        }

        self.draw_map(ui, rect, current, &to_screen);
        let painter = ui.painter_at(rect);
        self.hover_uv = response.hover_pos().map(to_uv);
        if let Some(pointer) = response.hover_pos() {
            // The brush outline: a circle of the brush radius in canvas
            // pixels (and its mirror image with mirroring).
            let r = self.brush.radius_in_uv as f32 * size;
            painter.circle_stroke(
                pointer,
                r + 1.0,
                Stroke::new(1.0, Color32::from_black_alpha(160)),
            );
            painter.circle_stroke(pointer, r, Stroke::new(1.0, Color32::WHITE));
            if self.brush.mirror {
                let uv = to_uv(pointer);
                painter.circle_stroke(
                    to_screen(DVec2::new(1.0 - uv.x, uv.y)),
                    r,
                    Stroke::new(1.0, Color32::from_white_alpha(120)),
                );
            }
        }
        dabs
    }

    /// The canvas's picture: the shown map (as this frame found it) over
    /// the UV square, the mesh's triangles, the midrib, and on the direction
    /// map its arrows.
    fn draw_map(
        &mut self,
        ui: &egui::Ui,
        rect: Rect,
        current: &Template,
        to_screen: &dyn Fn(DVec2) -> Pos2,
    ) {
        // The document as it is before this frame's dab (the app draws
        // again once the dab is applied).
        let shown = current;
        let image = map_image(shown, self.key, self.target);
        let options = egui::TextureOptions::NEAREST;
        match &mut self.texture {
            Some(texture) => texture.set(image, options),
            None => {
                self.texture = Some(ui.ctx().load_texture("paint map", image, options));
            }
        }
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
        let image_rect = Rect::from_min_max(
            to_screen(DVec2::new(0.0, 1.0)),
            to_screen(DVec2::new(1.0, 0.0)),
        );
        if let Some(texture) = &self.texture {
            painter.image(
                texture.id(),
                image_rect,
                Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                Color32::WHITE,
            );
        }
        let mesh = &current.mesh;
        let stroke = Stroke::new(0.5, Color32::from_black_alpha(140));
        let mut shapes = Vec::with_capacity(mesh.triangles.len() * 3);
        for tri in &mesh.triangles {
            for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                if a < b {
                    shapes.push(egui::Shape::line_segment(
                        [
                            to_screen(mesh.uvs[a as usize]),
                            to_screen(mesh.uvs[b as usize]),
                        ],
                        stroke,
                    ));
                }
            }
        }
        painter.extend(shapes);
        // The midrib.
        painter.line_segment(
            [
                to_screen(DVec2::new(0.5, 0.0)),
                to_screen(DVec2::new(0.5, 1.0)),
            ],
            Stroke::new(1.0, Color32::from_white_alpha(90)),
        );
        if self.target == PaintTarget::Direction {
            let map = &shown.maps.key_clamped(self.key).maps.direction;
            let n = 14;
            let cell = 1.0 / f64::from(n);
            for j in 0..n {
                for i in 0..n {
                    let uv = DVec2::new((f64::from(i) + 0.5) * cell, (f64::from(j) + 0.5) * cell);
                    let d = map.sample(uv);
                    let tip = uv + d.clamp_length_max(1.0) * cell * 0.8;
                    let from = to_screen(uv);
                    painter.arrow(
                        from,
                        to_screen(tip) - from,
                        Stroke::new(1.2, Color32::from_rgb(20, 40, 140)),
                    );
                }
            }
        }
    }

    /// The pending click as one dab, if there is one.
    fn flush_click(&mut self, project: &Project, template: usize) -> Option<Command> {
        let (point_in_uv, _) = self.pending_click.take()?;
        self.dab(project, template, point_in_uv)
    }
}
