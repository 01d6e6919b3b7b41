//! The dock: the enlarged image and, beside it, the windows of the Windows menu in a column
//! (`egui_tiles`: drag a tab to split or move, drag the gap to resize). Windows opened are
//! stacked top to bottom so they are seen together, up to [`MAX_STACKED`]; more become tabs of
//! the bottom group. Nothing covers the image, and every docked window scrolls, so at 1280×800
//! the whole of each can be reached.
//!
//! Generic over the windows: a window is a [`Window`] variant in [`Window::ALL`] plus a
//! `fn …_ui(ui: &mut egui::Ui, …)` drawing its contents, called from `DockBehavior::window_ui`.
//! Windows open and close only through [`Command::ShowWindow`]: [`Dock::sync`] adds a tab for a
//! window opened elsewhere (menu, shortcut, command) and removes one closed; closing a tab sends
//! the command.

use egui::Ui;
use egui_tiles::{Container, SimplificationOptions, Tile, TileId, Tiles, Tree, UiResponse};

use super::overlays::FrameTextures;
use super::views::{self, MainViewOutput};
use crate::workspace::{Command, Window, Workspace};

/// Share of the width the image gets beside the docked windows (they get 1).
const IMAGE_SHARE: f32 = 1.6;

/// How many groups of docked windows are stacked in the column beside the image before more
/// windows become tabs of the last group.
pub const MAX_STACKED: usize = 3;

/// What a tile shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pane {
    /// The enlarged view.
    Image,
    /// A window of the Windows menu.
    Window(Window),
}

/// The layout of the image and the docked windows (kept while the app runs).
pub struct Dock {
    tree: Tree<Pane>,
    /// The workspace's WMD layout requests followed so far.
    wmd_layouts: u64,
}

impl Default for Dock {
    fn default() -> Self {
        let mut tiles = Tiles::default();
        let image = tiles.insert_pane(Pane::Image);
        let root = tiles.insert_horizontal_tile(vec![image]);
        Self {
            tree: Tree::new(egui::Id::unique("eotn-dock"), root, tiles),
            wmd_layouts: 0,
        }
    }
}

impl std::fmt::Debug for Dock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dock")
            .field("docked", &self.docked())
            .finish_non_exhaustive()
    }
}

impl Dock {
    /// The windows that have a tab, in tile order.
    #[must_use]
    pub fn docked(&self) -> Vec<Window> {
        let mut out: Vec<Window> = self
            .tree
            .tiles
            .tiles()
            .filter_map(|t| match t {
                Tile::Pane(Pane::Window(w)) => Some(*w),
                _ => None,
            })
            .collect();
        out.sort_by_key(|w| Window::ALL.iter().position(|a| a == w));
        out
    }

    /// The docked windows whose contents are drawn (the active tab of each group), in
    /// [`Window::ALL`] order.
    #[must_use]
    pub fn shown(&self) -> Vec<Window> {
        let active = self.tree.active_tiles();
        let mut out: Vec<Window> = active
            .iter()
            .filter_map(|id| match self.tree.tiles.get_pane(id) {
                Some(Pane::Window(w)) => Some(*w),
                _ => None,
            })
            .collect();
        out.sort_by_key(|w| Window::ALL.iter().position(|a| a == w));
        out
    }

    /// Gives every open window a tab and removes the tabs of closed ones; arranges the WMD
    /// layout when the workspace asked for it again.
    pub fn sync(&mut self, state: &Workspace) {
        if state.wmd_layout_requests() != self.wmd_layouts {
            self.wmd_layouts = state.wmd_layout_requests();
            self.arrange_wmd(state);
            return;
        }
        for w in Window::ALL {
            let tile = self.tree.tiles.find_pane(&Pane::Window(w));
            match (state.window_open(w), tile) {
                (true, None) => self.add(w),
                (false, Some(id)) => {
                    self.tree.remove_recursively(id);
                }
                _ => {}
            }
        }
    }

    /// Docks `w` right of the image: below the windows already docked, in a column of at
    /// most [`MAX_STACKED`] groups so that windows opened together are seen together (the field
    /// view and the inspector highlight the same robot); beyond that, as the active tab of the
    /// column's last group. The first window makes the column.
    fn add(&mut self, w: Window) {
        let pane = self.tree.tiles.insert_pane(Pane::Window(w));
        if let Some(column) = self.window_column() {
            let last_tabs = match self.tree.tiles.get(column) {
                Some(Tile::Container(Container::Linear(l))) if l.children.len() >= MAX_STACKED => {
                    l.children.last().copied()
                }
                _ => None,
            };
            if let Some(id) = last_tabs
                && let Some(Tile::Container(Container::Tabs(t))) = self.tree.tiles.get_mut(id)
            {
                t.add_child(pane);
                t.set_active(pane);
                return;
            }
            let tabs = self.tree.tiles.insert_tab_tile(vec![pane]);
            if let Some(Tile::Container(Container::Linear(l))) = self.tree.tiles.get_mut(column) {
                l.add_child(tabs);
                return;
            }
        }
        // No column (none docked yet, or the user dragged the windows elsewhere): a group that
        // already holds windows takes the tab, else a new column right of the image.
        if let Some(id) = self.window_tabs()
            && let Some(Tile::Container(Container::Tabs(t))) = self.tree.tiles.get_mut(id)
        {
            t.add_child(pane);
            t.set_active(pane);
            return;
        }
        let tabs = self.tree.tiles.insert_tab_tile(vec![pane]);
        let column = self.tree.tiles.insert_vertical_tile(vec![tabs]);
        self.add_beside_image(column);
    }

    /// The World Model Debugger layout: the overhead view (the image) on the left; right of it the
    /// field view above the robots list, every other open window a tab beside the robots list.
    fn arrange_wmd(&mut self, state: &Workspace) {
        let mut tiles = Tiles::default();
        let image = tiles.insert_pane(Pane::Image);
        let field = tiles.insert_pane(Pane::Window(Window::FieldView));
        let field_tabs = tiles.insert_tab_tile(vec![field]);
        let mut rest = vec![tiles.insert_pane(Pane::Window(Window::Robots))];
        for w in Window::ALL {
            if state.window_open(w) && !matches!(w, Window::FieldView | Window::Robots) {
                rest.push(tiles.insert_pane(Pane::Window(w)));
            }
        }
        let robots = rest[0];
        let rest_tabs = tiles.insert_tab_tile(rest);
        if let Some(Tile::Container(Container::Tabs(t))) = tiles.get_mut(rest_tabs) {
            t.set_active(robots);
        }
        let mut column =
            egui_tiles::Linear::new(egui_tiles::LinearDir::Vertical, vec![field_tabs, rest_tabs]);
        column.shares.set_share(field_tabs, 2.0);
        column.shares.set_share(rest_tabs, 1.0);
        let column = tiles.insert_container(column);
        let mut row =
            egui_tiles::Linear::new(egui_tiles::LinearDir::Horizontal, vec![image, column]);
        row.shares.set_share(image, IMAGE_SHARE);
        row.shares.set_share(column, 1.0);
        let root = tiles.insert_container(row);
        self.tree = Tree::new(egui::Id::unique("eotn-dock"), root, tiles);
    }

    /// The windows of the column right of the image, top to bottom, each group's tabs in order
    /// (the WMD layout's test reads it).
    #[must_use]
    pub fn column_groups(&self) -> Vec<Vec<Window>> {
        let tiles = &self.tree.tiles;
        let Some(column) = self.window_column() else {
            return Vec::new();
        };
        let Some(Tile::Container(Container::Linear(l))) = tiles.get(column) else {
            return Vec::new();
        };
        l.children
            .iter()
            .map(|g| match tiles.get(*g) {
                Some(Tile::Container(c)) => c
                    .children()
                    .filter_map(|k| match tiles.get_pane(k) {
                        Some(Pane::Window(w)) => Some(*w),
                        _ => None,
                    })
                    .collect(),
                _ => Vec::new(),
            })
            .collect()
    }

    /// Whether tile `id` is a tab group holding a docked window.
    fn holds_windows(&self, id: TileId) -> bool {
        let tiles = &self.tree.tiles;
        match tiles.get(id) {
            Some(Tile::Container(Container::Tabs(t))) => t
                .children
                .iter()
                .any(|c| matches!(tiles.get_pane(c), Some(Pane::Window(_)))),
            _ => false,
        }
    }

    /// The vertical column of tab groups the docked windows are stacked in.
    fn window_column(&self) -> Option<TileId> {
        let tiles = &self.tree.tiles;
        tiles.tile_ids().find(|id| match tiles.get(*id) {
            Some(Tile::Container(Container::Linear(l))) => {
                l.dir == egui_tiles::LinearDir::Vertical
                    && l.children.iter().all(|c| {
                        tiles
                            .get(*c)
                            .is_some_and(|t| matches!(t, Tile::Container(Container::Tabs(_))))
                    })
                    && l.children.iter().any(|c| self.holds_windows(*c))
            }
            _ => false,
        })
    }

    /// A tab group holding docked windows, wherever it is.
    fn window_tabs(&self) -> Option<TileId> {
        self.tree
            .tiles
            .tile_ids()
            .find(|id| self.holds_windows(*id))
    }

    /// Puts `column` right of the image, the image keeping [`IMAGE_SHARE`] of the width.
    fn add_beside_image(&mut self, column: TileId) {
        let root = self.tree.root;
        if let Some(root) = root
            && let Some(Tile::Container(Container::Linear(l))) = self.tree.tiles.get_mut(root)
            && l.dir == egui_tiles::LinearDir::Horizontal
        {
            l.add_child(column);
            for child in l.children.clone() {
                let share = if child == column { 1.0 } else { IMAGE_SHARE };
                l.shares.set_share(child, share);
            }
            return;
        }
        let mut children: Vec<TileId> = root.into_iter().collect();
        children.push(column);
        let mut linear = egui_tiles::Linear::new(egui_tiles::LinearDir::Horizontal, children);
        if let Some(r) = root {
            linear.shares.set_share(r, IMAGE_SHARE);
        }
        linear.shares.set_share(column, 1.0);
        self.tree.root = Some(self.tree.tiles.insert_container(linear));
    }

    /// Draws the dock into `ui` (the central panel); returns what the image view reported.
    pub fn ui(&mut self, ui: &mut Ui, behavior: &mut DockBehavior<'_>) -> MainViewOutput {
        self.tree.ui(behavior, ui);
        self.give_every_window_a_tab();
        behavior.view
    }

    /// Puts every docked window that lost its tab back into a tab group of its own. Dropping a
    /// tab on a group's side splits the group: `egui_tiles` then makes a row or column inside
    /// the tab group, whose windows have no tab bar (no title, no close button). The image
    /// keeps no tab: it is never closed.
    pub fn give_every_window_a_tab(&mut self) {
        let tiles = &self.tree.tiles;
        let bare: Vec<TileId> = tiles
            .tile_ids()
            .filter(|id| matches!(tiles.get_pane(id), Some(Pane::Window(_))))
            .filter(|id| {
                tiles
                    .parent_of(*id)
                    .and_then(|p| tiles.get_container(p))
                    .is_none_or(|c| c.kind() != egui_tiles::ContainerKind::Tabs)
            })
            .collect();
        for pane in bare {
            let parent = self.tree.tiles.parent_of(pane);
            let tabs = self.tree.tiles.insert_tab_tile(vec![pane]);
            match parent.and_then(|p| self.tree.tiles.get_mut(p)) {
                Some(Tile::Container(c)) => {
                    let _ = c.replace_child(pane, tabs);
                }
                _ => {
                    if self.tree.root == Some(pane) {
                        self.tree.root = Some(tabs);
                    }
                }
            }
        }
    }

    /// Each docked window's tab group: the window and the kind of container holding it (`Tabs`
    /// for every window, once [`Self::give_every_window_a_tab`] has run).
    #[must_use]
    pub fn window_parents(&self) -> Vec<(Window, Option<egui_tiles::ContainerKind>)> {
        let tiles = &self.tree.tiles;
        tiles
            .tile_ids()
            .filter_map(|id| match tiles.get_pane(&id) {
                Some(Pane::Window(w)) => Some((
                    *w,
                    tiles
                        .parent_of(id)
                        .and_then(|p| tiles.get_container(p))
                        .map(egui_tiles::Container::kind),
                )),
                _ => None,
            })
            .collect()
    }

    /// The tree, for tests that rearrange it as a drag would.
    pub fn tree_mut(&mut self) -> &mut Tree<Pane> {
        &mut self.tree
    }

    /// The title a tab shows for tile `id`: a window's name, or for a row or column of windows
    /// inside a tab group, their names joined (`egui_tiles` says "Horizontal").
    #[must_use]
    pub fn tab_title(tiles: &Tiles<Pane>, id: TileId) -> String {
        match tiles.get(id) {
            Some(Tile::Pane(Pane::Image)) => "Image".to_owned(),
            Some(Tile::Pane(Pane::Window(w))) => w.name().to_owned(),
            Some(Tile::Container(c)) => {
                let names: Vec<String> = c.children().map(|k| Self::tab_title(tiles, *k)).collect();
                names.join(" + ")
            }
            None => String::new(),
        }
    }
}

/// What the dock's panes draw from, for one frame.
pub struct DockBehavior<'a> {
    /// The workspace.
    pub state: &'a Workspace,
    /// The frame's textures.
    pub tex: Option<&'a FrameTextures>,
    /// The U–V plane's cached image.
    pub uv_plane: &'a mut super::uv_plane::UvPlane,
    /// The file names typed in the overhead calibration window.
    pub overhead_paths: &'a mut super::calibration_window::OverheadPaths,
    /// What the robots window is editing.
    pub robots: &'a mut super::robots_panel::RobotsPanel,
    /// Where the panes' commands go.
    pub commands: &'a mut Vec<Command>,
    /// A file dialog a pane asks for.
    pub dialog: &'a mut Option<(super::file_dialog::FileAction, Option<String>)>,
    /// What the image view reported.
    pub view: MainViewOutput,
    /// The textures of cameras shown beside the focused one.
    pub beside: &'a super::side_by_side::BesideTextures,
    /// Cameras side by side: where each camera's image was drawn.
    pub panes: Vec<super::side_by_side::DrawnPane>,
}

impl DockBehavior<'_> {
    /// The contents of window `w`: one `…_ui` function per window (add a window here).
    fn window_ui(&mut self, ui: &mut Ui, w: Window) {
        let (state, commands) = (self.state, &mut *self.commands);
        match w {
            Window::Sensors => super::sensors_dialog::sensors_ui(ui, state),
            Window::UvPlane => self.uv_plane.ui(ui, state, commands),
            Window::TryEdit => super::classify_panel::try_edit_panel_ui(ui, state, commands),
            Window::Inspector => super::inspector::inspector_ui(ui, state, commands),
            Window::Parameters => {
                super::params_panel::params_panel_ui(ui, state, commands, self.dialog);
            }
            Window::FieldView => super::field_view::field_view_ui(ui, state, commands),
            Window::Calibration => {
                super::calibration_window::calibration_ui(
                    ui,
                    state,
                    self.overhead_paths,
                    commands,
                    self.dialog,
                );
            }
            Window::Robots => super::robots_panel::robots_ui(ui, state, self.robots, commands),
            Window::Coverage => super::coverage_panel::coverage_ui(ui, state, commands),
            Window::Bookmarks => super::bookmarks_panel::bookmarks_ui(ui, state, commands),
            Window::Connect | Window::SourceSettings | Window::Record => {
                ui.weak("a Camera dialog");
            }
        }
    }
}

impl egui_tiles::Behavior<Pane> for DockBehavior<'_> {
    fn pane_ui(&mut self, ui: &mut Ui, _tile_id: TileId, pane: &mut Pane) -> UiResponse {
        match *pane {
            Pane::Image if !self.state.camera_panes().is_empty() => {
                let out = super::side_by_side::side_by_side_ui(
                    ui,
                    self.state,
                    self.tex,
                    self.beside,
                    self.commands,
                );
                self.view = out.focused;
                self.panes = out.panes;
            }
            Pane::Image => {
                self.view = views::main_view_ui(ui, self.state, self.tex, self.commands);
            }
            Pane::Window(w) => {
                egui::Frame::new().inner_margin(6.0).show(ui, |ui| {
                    egui::ScrollArea::both()
                        .id_salt(("dock-scroll", w.name()))
                        .auto_shrink([false, false])
                        .show(ui, |ui| self.window_ui(ui, w));
                });
            }
        }
        UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        match pane {
            Pane::Image => "Image".into(),
            Pane::Window(w) => w.name().into(),
        }
    }

    fn tab_title_for_tile(&mut self, tiles: &Tiles<Pane>, tile_id: TileId) -> egui::WidgetText {
        Dock::tab_title(tiles, tile_id).into()
    }

    fn is_tab_closable(&self, tiles: &Tiles<Pane>, tile_id: TileId) -> bool {
        matches!(tiles.get_pane(&tile_id), Some(Pane::Window(_)))
    }

    fn on_tab_close(&mut self, tiles: &mut Tiles<Pane>, tile_id: TileId) -> bool {
        if let Some(Pane::Window(w)) = tiles.get_pane(&tile_id) {
            self.commands.push(Command::ShowWindow(*w, false));
        }
        // The tab goes when the command has closed the window (`Dock::sync`).
        false
    }

    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions {
            // A single docked window keeps its tab: its title and close button.
            prune_single_child_tabs: false,
            prune_single_child_containers: false,
            all_panes_must_have_tabs: false,
            ..SimplificationOptions::default()
        }
    }

    fn min_size(&self) -> f32 {
        120.0
    }
}
