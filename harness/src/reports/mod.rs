//! What the jobs render with: SVG [`figures`], an episode's self-contained HTML
//! replay page ([`replay_html`]), the junction as every picture of an episode draws it
//! ([`junction_scene`], also the Python frame's) and printed documents as text, Markdown
//! or HTML ([`Document`], [`Grid`]); each job builds its own report's document.
//!
//! The face of this part is what it re-exports here, and the [`figures`] module.

pub mod figures;
pub(crate) mod replay_page;
pub(crate) mod scene;
pub(crate) mod tables;

pub use replay_page::replay_html;
pub use scene::{
    CROSS_VIEW, FRONT_BAND, Head, JunctionScene, Lamp, Segment, Shows, gap_to_car, junction_scene, nearest_in_path,
    vehicle_quad,
};
pub use tables::{Block, Document, Grid};
