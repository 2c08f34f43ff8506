//! Quadric error metric algebra in f64, with no mesh types.
//!
//! - [`Quadric`]: the symmetric 4x4 error quadric of Garland and Heckbert ("Surface
//!   Simplification Using Quadric Error Metrics", SIGGRAPH 97), stored as 10 f64.
//! - [`optimal_placement`]: where a contracted pair's new vertex goes, with the paper's
//!   fallback chain and a relative singularity test.
//! - [`AttributeQuadric`]: the error of texture coordinates, normals and colours beside
//!   the position (Garland–Heckbert 98, in Hoppe 99's form).
//! - [`Frame`]: normalised coordinates and conversion of errors back to world units and
//!   to fractions of the bounding-box diagonal.
//!
//! ```
//! use glam::DVec3;
//! use qem_core::{optimal_placement, PlacementRule, Quadric};
//! // A cube corner: three faces meeting at (1, 1, 1).
//! let q = Quadric::from_plane(DVec3::X, -1.0)
//!     + Quadric::from_plane(DVec3::Y, -1.0)
//!     + Quadric::from_plane(DVec3::Z, -1.0);
//! let p = optimal_placement(&q, DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
//! assert_eq!(p.rule, PlacementRule::Optimal);
//! assert_eq!(p.position, DVec3::ONE);
//! assert_eq!(p.cost, 0.0);
//! ```
#![forbid(unsafe_code)]

mod attribute;
mod frame;
mod plane;
mod quadric;
mod solve;

pub use attribute::{AttributeQuadric, MAX_COMPONENTS};
pub use frame::Frame;
pub use glam::DVec3;
pub use plane::WeightedPlane;
pub use quadric::{unit_normal_and_area, Quadric};
pub use solve::{
    endpoint_placement, minimize, minimize_by_cofactors, optimal_placement, segment_placement,
    solve_first_placement, Placement, PlacementRule, FLAT_SEGMENT_RATIO,
    SINGULAR_DETERMINANT_RATIO, SINGULAR_PIVOT_RATIO,
};
