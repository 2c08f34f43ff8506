//! What a simplification may do: [`SimplifyOptions`] and the small enums it is made of.

use crate::attributes::ChannelKind;
use crate::clean::CleanOptions;
use qem_core::Frame;

/// A length given either relative to the input or in model units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// A fraction of the input's bounding-box diagonal (0.01 = 1% of the diagonal).
    DiagonalFraction(f64),
    /// A distance in the input's own units.
    Absolute(f64),
}

impl Length {
    /// This length in the normalised units of `frame`; negative or NaN becomes 0.
    pub(crate) fn normalized(self, frame: &Frame) -> f64 {
        let d = match self {
            Length::DiagonalFraction(f) => frame.diagonal_fraction_to_distance(f),
            Length::Absolute(d) => frame.distance_to_normalized(d),
        };
        if d > 0.0 {
            d
        } else {
            0.0
        }
    }
}

/// How many triangles to aim for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// Stop at or below this many triangles.
    Triangles(usize),
    /// Stop at or below this fraction of the input's triangles (as given, before
    /// cleaning), rounded to the nearest count (1% of 5,856 triangles is 59, the count
    /// nearest the 58.56 asked), and never below one triangle: the engine keeps a mesh's
    /// last triangle (it refuses the contraction that would remove it), so a fraction
    /// of a small mesh that rounds to none asks for that last one (1% of 40 triangles
    /// is 1).
    Ratio(f64),
    /// No count target: contract until the error bound or until no pair is left.
    None,
}

impl Target {
    /// The triangle count this target asks of an input of `triangles_in` triangles (as
    /// loaded): [`Triangles`](Self::Triangles) as given, [`Ratio`](Self::Ratio) as
    /// documented there, 0 for [`None`](Self::None).
    ///
    /// ```
    /// use qem_mesh::simplify::Target;
    /// assert_eq!(Target::Ratio(0.01).triangles_for(5856), 59);
    /// assert_eq!(Target::Ratio(0.01).triangles_for(40), 1);
    /// ```
    pub fn triangles_for(self, triangles_in: usize) -> usize {
        match self {
            Target::Triangles(n) => n,
            Target::Ratio(r) if r > 0.0 => ((r.min(1.0) * triangles_in as f64).round() as usize)
                .clamp(1.min(triangles_in), triangles_in),
            Target::Ratio(_) => 1.min(triangles_in),
            Target::None => 0,
        }
    }
}

/// How the new vertex of a contracted pair is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlacementMode {
    /// The quadric's minimum, with Garland–Heckbert's fallback chain (segment, then
    /// ends and midpoint).
    Optimal,
    /// Only the cheapest of the two ends and the midpoint.
    EndpointOrMidpoint,
    /// Garland–Heckbert's rule as published: the quadric's minimum whenever the 3x3
    /// solve succeeds, without comparing it with the segment and the ends (which
    /// [`Optimal`](Self::Optimal) does, to guard against rounding in nearly singular
    /// solves); the fallback chain only when the solve fails. The solve is by
    /// cofactors ([`qem_core::minimize_by_cofactors`], about a fifth of the time of
    /// the elimination [`Optimal`](Self::Optimal) uses). Used by
    /// [`SimplifyOptions::FAST`].
    SolveFirst,
}

/// How face planes are weighted in the vertex quadrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Weighting {
    /// By triangle area (large faces count more than slivers).
    Area,
    /// Every face plane with weight 1.
    Unweighted,
    /// A blend: face weight `area + s · Ā`, where `Ā` is the mean area of the cleaned
    /// input's faces. `s = 0` is [`Area`](Self::Area) (bit for bit); as `s` grows the
    /// weights tend to equal, i.e. to [`Unweighted`](Self::Unweighted) up to a common
    /// factor, which changes no decision (an infinite `s` is `Unweighted`). A negative
    /// or NaN `s` counts as 0.
    ///
    /// Why this form: area weights let a large flat region outvote the small faces of
    /// a sharp feature (tips get shaved: larger Hausdorff distance), unit weights let
    /// slivers and tiny faces count as much as large ones (larger mean error); adding a
    /// constant lifts the small faces to at least `s · Ā` while large faces still count
    /// by area. Using the *mean* area keeps it scale-free: scaling the mesh scales every
    /// weight by the same factor.
    Mixed(f64),
}

impl Weighting {
    /// Whether the planes' weights are areas (then they scale with a frame's scale
    /// squared, [`qem_core::Frame::quadric_to_world`]) rather than numbers.
    pub(crate) fn area_weighted(self) -> bool {
        self.area_offset(1.0).is_some()
    }

    /// The constant added to every face's area, `s · Ā` (0 for [`Area`](Self::Area)),
    /// or `None` for unit weights ([`Unweighted`](Self::Unweighted), or an infinite
    /// `s`). `mean_area` is `Ā`.
    pub(crate) fn area_offset(self, mean_area: f64) -> Option<f64> {
        match self {
            Weighting::Area => Some(0.0),
            Weighting::Unweighted => None,
            Weighting::Mixed(s) if s == f64::INFINITY => None,
            Weighting::Mixed(s) if s > 0.0 => Some(s * mean_area),
            Weighting::Mixed(_) => Some(0.0),
        }
    }
}

/// What happens at the border of an open surface (edges with exactly one face).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoundaryMode {
    /// No special treatment: a flat open sheet can then shrink away from its border at
    /// zero cost, because sliding along the sheet's plane costs nothing.
    Free,
    /// Garland–Heckbert's constraint planes (§6.2 of the paper): through each border
    /// edge, perpendicular to its face, added to the quadrics of both ends with this
    /// weight. The plane's weight is `w · |edge|²` with [`Weighting::Area`] (an area,
    /// like the face planes it competes with, so the weight is scale-free), `w` with
    /// [`Weighting::Unweighted`], and `w · (|edge|² + s · Ā)` with
    /// [`Weighting::Mixed`]`(s)` (the same offset as the faces get, so the ratio of
    /// border to face weight stays between the two other modes'). Moving a border vertex off its border line then costs
    /// about `w` times as much as moving it the same distance off its faces' plane.
    ///
    /// Also the *loop rule*: an edge whose two ends are on a border must be a border
    /// edge itself, and may not close a loop of three border edges, so border loops are
    /// never pinched, merged or closed (counted in
    /// [`Refusals::border`](super::Refusals::border)), unless the run is stuck and the
    /// ladder of relaxations climbs [`RelaxationStep::BorderLoops`](super::RelaxationStep::BorderLoops).
    Planes(f64),
    /// Border vertices never move and are never removed, like [locked
    /// vertices](SimplifyOptions::locked_vertices): the border comes out exactly as it
    /// went in. The loop rule of [`Planes`](Self::Planes) applies too.
    Locked,
}

/// Which quadric a contracted pair gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuadricMode {
    /// Garland–Heckbert's `Q_a + Q_b`: planes shared by both ends (the faces around the
    /// edge) count twice, and again at every later contraction that meets them.
    Sum,
    /// The quadric of the *union* of the two plane sets, by inclusion–exclusion:
    /// `Q(A ∪ B) = Q(A) + Q(B) − Q(A ∩ B)`, with the intersection quadrics kept on edges
    /// and triangles (Edelsbrunner, *Geometry and Topology for Mesh Generation*, ch. 4).
    /// Every plane counts once. Costs two quadrics per edge and one per face of memory
    /// and a little bookkeeping per contraction.
    Exact,
}

/// Which unconnected vertex pairs may become virtual pairs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VirtualPairs {
    /// Any two close vertices that share no edge (Garland–Heckbert): also closes gaps
    /// and cracks inside one part.
    Any,
    /// Only vertices of different connected components of the cleaned input: parts
    /// merge, but a part never folds onto itself.
    BetweenComponents,
}

/// In which order pairs are contracted: a policy of the one engine. Every other option
/// works in both orders (virtual pairs, topology preservation, exact quadrics, the
/// orientation check, locks, borders, levels of detail, the error bound), with the
/// same checks and the same attempt of each pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContractionOrder {
    /// Garland–Heckbert's: always the cheapest pair next (a heap of every edge and
    /// virtual pair), the pairs at the new vertex re-costed after every contraction.
    /// A refused pair waits until one of its ends moves. With the other defaults it
    /// takes about 2.5 times as long as [`Passes`](Self::Passes), for the same accuracy
    /// (BENCHMARKS.md, "Passes with every default option", "Which order is the
    /// default").
    Greedy,
    /// meshoptimizer's: in passes, each costing every pair once and contracting a batch
    /// of the cheapest, no two sharing a vertex (a pair whose cost fell during a pass
    /// waits for the next one). The default. With the other defaults, against
    /// [`Greedy`](Self::Greedy) (BENCHMARKS.md, "Passes with every default option",
    /// "Which order is the default"): about 0.4 times the time; on the 9 clean corpus
    /// scans as accurate (mean error at most the best of five peers' in 23 of 27 cases
    /// against 22, Hausdorff distance in 15 against 15, no face facing away at 0.1); on
    /// 40 messy corpus meshes the same (geometric means of 80 runs, Hausdorff distance
    /// 1.000x, mean distance 1.010x). A pair the orientation check refuses is ranked at
    /// the waivers' penalty in later passes and tried without the check next time,
    /// unless one of its ends moves first. With a
    /// [`max_error`](SimplifyOptions::max_error) bound, a pair over the bound is never
    /// contracted but does not end the run either; the run stops with
    /// [`StopReason::MaxErrorReached`](super::StopReason::MaxErrorReached) when a pass
    /// contracts nothing and met at least one pair over the bound (and with
    /// [`StopReason::NoValidPair`](super::StopReason::NoValidPair) when the checks
    /// refused every pair under it). [`SimplifyOptions::FAST`] is the defaults with
    /// this order, summed quadrics, no orientation check and
    /// [`PlacementMode::SolveFirst`].
    Passes,
}

/// Options of a simplification. Start from [`SimplifyOptions::DEFAULT`] and adjust
/// with the `with_*` setters.
///
/// ```
/// use qem_mesh::simplify::{BoundaryMode, Length, SimplifyOptions, Target};
/// let options = SimplifyOptions::DEFAULT
///     .with_target(Target::Ratio(0.1))
///     .with_max_error(Some(Length::DiagonalFraction(0.001)))
///     .with_boundary(BoundaryMode::Locked)
///     .with_locked_vertices(vec![0, 7]);
/// assert_eq!(options.target, Target::Ratio(0.1));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// The triangle count to reach. Default: `Target::Ratio(0.5)`.
    pub target: Target,
    /// Stop before the first contraction whose error would exceed this distance (see
    /// [`SimplifyReport::max_error`](super::SimplifyReport::max_error) for what the
    /// error measures); in [`ContractionOrder::Passes`], never contract a pair over it
    /// (see there). Default: `None`.
    pub max_error: Option<Length>,
    /// Vertex pairs closer than this that share no edge are candidates too ("virtual
    /// pairs"), so separate parts can merge; zero means edges only. Ignored (no virtual
    /// pairs) with [`preserve_topology`](Self::preserve_topology). Default:
    /// `Length::DiagonalFraction(0.0)`.
    pub pair_threshold: Length,
    /// At most this many virtual pairs per vertex, the nearest first. Default: 8.
    pub max_virtual_pairs_per_vertex: usize,
    /// Which close vertices may pair up. Default: `VirtualPairs::Any`.
    pub virtual_pairs: VirtualPairs,
    /// Where the new vertex goes. Default: `PlacementMode::Optimal`.
    pub placement: PlacementMode,
    /// How face planes are weighted. Default:
    /// `Weighting::Mixed(DEFAULT_WEIGHTING_MIX)` (see [`DEFAULT_WEIGHTING_MIX`] for how
    /// it was chosen).
    pub weighting: Weighting,
    /// Which quadric a contracted pair gets. Default: `QuadricMode::Exact` (measured
    /// with the weighting, see [`DEFAULT_WEIGHTING_MIX`]).
    pub quadrics: QuadricMode,
    /// What happens at borders. Default: `BoundaryMode::Planes(DEFAULT_BOUNDARY_WEIGHT)`
    /// (see [`DEFAULT_BOUNDARY_WEIGHT`] for how it was chosen).
    pub boundary: BoundaryMode,
    /// Refuse a contraction that turns the normal of a surviving face by more than this
    /// many degrees, or that leaves it pointing more than 90° away from the input face
    /// it descends from (a fold-over in several small steps); 180 or more turns the
    /// check off (zero-area faces are refused regardless). Counted in
    /// [`Refusals::flip`](super::Refusals::flip).
    /// Default: [`DEFAULT_MAX_NORMAL_ANGLE`] degrees.
    pub max_normal_angle: f64,
    /// Refuse a contraction that leaves a surviving face with a quality below this
    /// *and* below the face's quality before. Quality is `4√3·area / (l₀² + l₁² + l₂²)`:
    /// 1 for an equilateral triangle, 0 for a degenerate one; 0 turns the check off.
    /// Counted in [`Refusals::sliver`](super::Refusals::sliver).
    /// Default: [`DEFAULT_MIN_TRIANGLE_QUALITY`].
    pub min_triangle_quality: f64,
    /// Refuse a contraction that leaves a moved face facing away from the input surface
    /// nearest to the face's centroid: each of the (up to 8) input triangles nearest to
    /// it, within 1.5 times the nearest one's distance, must have a positive dot product
    /// with the face's normal (zero-area input triangles have no say). Catches what the
    /// fold-over check cannot: a large face over a crease or a thin part whose centroid
    /// ends up nearest to the surface's other side. Costs one nearest-triangle search
    /// per moved face, against an index built once over the cleaned input. A refused
    /// pair is not dropped but queued again at 32 times its cost (at least the cost of
    /// moving it 1e-6 of the normalised diagonal), and contracted without the check when
    /// it comes up again, unless it was re-costed meanwhile: at extreme ratios refusing
    /// for good would force far costlier contractions elsewhere. (In
    /// [`ContractionOrder::Passes`]: ranked at that cost in the later passes and
    /// contracted without the check when next attempted, unless one of its ends moves
    /// first, which has it costed and checked afresh.) Counted in
    /// [`Refusals::orientation`](super::Refusals::orientation).
    /// Default: `true`.
    pub orientation_check: bool,
    /// Keep the topology: only contract edges that pass the link condition (with the
    /// border extension), never at non-manifold vertices or edges, and no virtual
    /// pairs. The Euler characteristic, the number of components and the number of
    /// border loops are then those of the cleaned input. Default: `false`.
    pub preserve_topology: bool,
    /// Vertices that must come out unmoved and present: indices into the input mesh as
    /// given (before cleaning; a vertex welded to others locks the vertex they became,
    /// and a vertex no face uses is ignored). A locked vertex may absorb a neighbour
    /// but never moves or disappears. Default: empty.
    pub locked_vertices: Vec<u32>,
    /// The cleaning passes run before simplification. Default: `CleanOptions::DEFAULT`.
    pub clean: CleanOptions,
    /// In which order pairs are contracted. Default: `ContractionOrder::Passes`.
    pub order: ContractionOrder,
    /// Stop when no pair passes every check, rather than climb the ladder of
    /// relaxations ([`RelaxationStep`](super::RelaxationStep)): the run then stops
    /// short with [`StopReason::NoValidPair`](super::StopReason::NoValidPair) where
    /// the relaxed checks would have let it go on. Default: `false`.
    pub strict: bool,
    /// Pair contraction (every option above) or vertex clustering (see [`Method`]).
    /// Default: `Method::Contraction`.
    pub method: Method,
    /// How much texture coordinates, normals and colours weigh against positions, for
    /// meshes that carry them (see [`crate::attributes`]). Default:
    /// `AttributeWeights::DEFAULT`.
    pub attribute_weights: AttributeWeights,
}

/// How much each kind of channel weighs against positions (in the normalised frame,
/// where the bounding box spans about 2): an attribute difference of 1 costs as much
/// as a distance of `weight` there.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct AttributeWeights {
    /// Texture coordinates. Default 0.3.
    pub uv: f64,
    /// Normals (unit vectors). Default 0.15.
    pub normal: f64,
    /// Colours (0–1). Default 1.
    pub colour: f64,
    /// Generic channels. Default 1.
    pub generic: f64,
}

impl AttributeWeights {
    /// The defaults. uv 0.3 and normal 0.15, from 1/0.5, 0.3/0.15 and 0.1/0.05 run on
    /// the corpus's attributed meshes against meshoptimizer's update with the same
    /// weights (BENCHMARKS.md, "Attributes"): 1/0.5 cost the most geometry (up to 1.6
    /// times the positions-only mean error), the two lower pairs about the same uv
    /// error as each other. Colours and generic channels are not measured yet.
    pub const DEFAULT: AttributeWeights = AttributeWeights {
        uv: 0.3,
        normal: 0.15,
        colour: 1.0,
        generic: 1.0,
    };

    /// The weights with `kind`'s set to `weight`.
    pub const fn with(mut self, kind: ChannelKind, weight: f64) -> Self {
        match kind {
            ChannelKind::TexCoord => self.uv = weight,
            ChannelKind::Normal => self.normal = weight,
            ChannelKind::Color => self.colour = weight,
            ChannelKind::Generic => self.generic = weight,
        }
        self
    }

    /// The weight of a channel of `kind`.
    pub fn of(&self, kind: ChannelKind) -> f64 {
        match kind {
            ChannelKind::TexCoord => self.uv,
            ChannelKind::Normal => self.normal,
            ChannelKind::Color => self.colour,
            ChannelKind::Generic => self.generic,
        }
    }
}

impl Default for AttributeWeights {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// How a mesh is simplified.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Garland–Heckbert pair contraction, the engine every other option of
    /// [`SimplifyOptions`] describes.
    Contraction,
    /// Vertex clustering on a uniform grid ([`crate::cluster`]): one vertex per cell
    /// at the cell's quadric optimum, the grid chosen to reach the target. Many times
    /// faster, works on any input and always gets near the count, but keeps neither
    /// topology nor the contraction's accuracy. It reads only the target (each level
    /// of [`simplify_levels`](super::simplify_levels) is clustered from the input);
    /// the options it cannot honour (locks, a locked boundary, topology preservation,
    /// an error bound, no count target) are refused
    /// ([`SimplifyError::NotWithClustering`](super::SimplifyError::NotWithClustering)).
    Clustering,
}

/// The default border-plane weight of [`BoundaryMode::Planes`]: moving a border vertex
/// off its border line costs about ten times as much as moving it as far off its
/// faces' plane (meshoptimizer weighs its border edges by 10 too: `kEdgeWeightBorder`
/// in its `simplifier.cpp`).
///
/// Measured on 2026-12-05 against the earlier default of 1 (`scripts/compare_peers.py`,
/// the 9 clean scans at 0.5, 0.1 and 0.01 against five peers; BENCHMARKS.md "Border
/// weight"): cases with a Hausdorff distance at most the best peer's 15/27 → 18/27,
/// mean error at most the best peer's 23/27 both; the Hausdorff distance of the open
/// scans fell most (drc_bun_zipper 0.111% → 0.042% at 0.5, cgal_ChineseDragon_10kv
/// 4.80% → 3.68% at 0.01), the closed ones are unchanged. Seams keep planes of
/// [`SEAM_PLANE_WEIGHT`]. (First chosen with `examples/quality_sweep.rs` on 7 meshes
/// with borders, ratios 0.1 and 0.02, weights 0.1 to 100: no weight lost a border
/// loop; weight 1 changed the area least, larger weights kept the border length
/// closer: 1.8% → 0.3% at 0.1.)
pub const DEFAULT_BOUNDARY_WEIGHT: f64 = 10.0;

/// The weight of the constraint planes through seam edges (a UV seam, a hard normal,
/// a colour or material border: [`BoundaryMode::Planes`] with a weight above 0 gives
/// them), whatever the border weight.
///
/// Why not the border weight: at 10, seam planes cost the textured meshes' geometry
/// (pymeshlab_bunny10k_textured at 0.1: mean distance 0.136% → 0.248% of the diagonal,
/// `qem measure --min-samples 200000`); 1 is the weight they had before the border
/// weight went to 10. (meshoptimizer weighs its seam edges less than its borders too.)
pub const SEAM_PLANE_WEIGHT: f64 = 1.0;

/// The default mix `s` of [`Weighting::Mixed`] (face weight `area + s · mean area`),
/// used with [`QuadricMode::Exact`].
///
/// Measured with `scripts/compare_peers.py` on the 9 clean corpus scans at ratios 0.5,
/// 0.1 and 0.01 (27 cases) against meshoptimizer, MeshLab's QEM and pyfqmr, counting
/// the cases where qem's mean error / Hausdorff distance is at most the best peer's
/// (BENCHMARKS.md, "Blended plane weights"): area weights with summed quadrics (the
/// old default) 26/27 and 8/27; unit weights with exact quadrics 16/27 and 20/27;
/// exact quadrics with `s` = 0.25, 0.5, 0.75, 1, 2, 4: mean 25, 25, 25, 23, 22, 22 and
/// Hausdorff 15, 17, 18, 18, 18, 20; summed quadrics with `s = 1`: 19/27 and 14/27.
/// 0.75 is the only setting measured that keeps 25/27 on the mean with 18/27 on
/// Hausdorff (a margin on both goals, ≥ 22 and ≥ 17); flipped faces at ratio 0.1 stay
/// at 0.19% or less (old default 0.35%), and no more border loops are lost. The price
/// is time: on the 871k-triangle dragon at ratio 0.1 the simplification takes about
/// 18% longer than with area weights and summed quadrics (5.9 s against 5.0 s, best
/// of 3 on a loaded 2-core machine).
pub const DEFAULT_WEIGHTING_MIX: f64 = 0.75;

/// The default of [`SimplifyOptions::max_normal_angle`], in degrees.
///
/// Measured on 13 corpus meshes at ratios 0.1 and 0.02: with the check at 90° no output
/// face points away from its input face (without it: 2.0% and 2.4% on average, 18% on
/// a CAD soup) and every run reaches its target; 60° and 45° also give 0% but one run
/// of 13 stops short at 0.02, for no gain in error.
pub const DEFAULT_MAX_NORMAL_ANGLE: f64 = 90.0;

/// The default of [`SimplifyOptions::min_triangle_quality`]: off.
///
/// Measured on the same 13 meshes: 0.1 raises the largest error by 1.5x (geometric
/// mean, ratio 0.1) and one run stops short of its target; the fold-over check alone
/// already gives 0% flipped faces.
pub const DEFAULT_MIN_TRIANGLE_QUALITY: f64 = 0.0;

impl SimplifyOptions {
    /// The defaults listed on each field.
    pub const DEFAULT: SimplifyOptions = SimplifyOptions {
        target: Target::Ratio(0.5),
        max_error: None,
        pair_threshold: Length::DiagonalFraction(0.0),
        max_virtual_pairs_per_vertex: 8,
        virtual_pairs: VirtualPairs::Any,
        placement: PlacementMode::Optimal,
        weighting: Weighting::Mixed(DEFAULT_WEIGHTING_MIX),
        quadrics: QuadricMode::Exact,
        boundary: BoundaryMode::Planes(DEFAULT_BOUNDARY_WEIGHT),
        max_normal_angle: DEFAULT_MAX_NORMAL_ANGLE,
        min_triangle_quality: DEFAULT_MIN_TRIANGLE_QUALITY,
        orientation_check: true,
        preserve_topology: false,
        locked_vertices: Vec::new(),
        clean: CleanOptions::DEFAULT,
        order: ContractionOrder::Passes,
        strict: false,
        method: Method::Contraction,
        attribute_weights: AttributeWeights::DEFAULT,
    };

    /// [`DEFAULT`](Self::DEFAULT) in [`ContractionOrder::Passes`], with summed quadrics
    /// ([`QuadricMode::Sum`]) and the orientation check off for speed, and the cheaper
    /// placement rule [`PlacementMode::SolveFirst`].
    ///
    /// `FAST.with_orientation_check(true)` turns the check back on: on the 9 clean
    /// corpus scans at ratio 0.1, faces facing away from the nearest input face went
    /// from 0.01–0.35% on 4 scans to 0.04% on one, and the simplification took about
    /// 1.9 times as long (BENCHMARKS.md, "The orientation check in passes"); with
    /// [`QuadricMode::Exact`] as well, every default quality option is on
    /// ("Every default quality option in passes").
    ///
    /// ```
    /// use qem_mesh::simplify::{simplify, SimplifyOptions, Target};
    /// use qem_mesh::IndexedMesh;
    /// // An octahedron: 8 triangles.
    /// let positions = vec![
    ///     [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
    ///     [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0],
    /// ];
    /// let triangles = vec![
    ///     [0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
    ///     [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5],
    /// ];
    /// let mesh = IndexedMesh::new(positions, triangles);
    /// let out = simplify(&mesh, &SimplifyOptions::FAST.with_target(Target::Triangles(4)))?;
    /// assert!(out.mesh.triangle_count() <= 4);
    /// # Ok::<(), qem_mesh::simplify::SimplifyError>(())
    /// ```
    pub const FAST: SimplifyOptions = SimplifyOptions {
        target: Target::Ratio(0.5),
        max_error: None,
        pair_threshold: Length::DiagonalFraction(0.0),
        max_virtual_pairs_per_vertex: 8,
        virtual_pairs: VirtualPairs::Any,
        placement: PlacementMode::SolveFirst,
        weighting: Weighting::Mixed(DEFAULT_WEIGHTING_MIX),
        quadrics: QuadricMode::Sum,
        boundary: BoundaryMode::Planes(DEFAULT_BOUNDARY_WEIGHT),
        max_normal_angle: DEFAULT_MAX_NORMAL_ANGLE,
        min_triangle_quality: DEFAULT_MIN_TRIANGLE_QUALITY,
        orientation_check: false,
        preserve_topology: false,
        locked_vertices: Vec::new(),
        clean: CleanOptions::DEFAULT,
        order: ContractionOrder::Passes,
        strict: false,
        method: Method::Contraction,
        attribute_weights: AttributeWeights::DEFAULT,
    };

    /// [`DEFAULT`](Self::DEFAULT) with [`Method::Clustering`]: vertex clustering
    /// instead of pair contraction.
    ///
    /// ```
    /// use qem_mesh::simplify::{simplify, SimplifyOptions, Target};
    /// use qem_mesh::IndexedMesh;
    /// // A 30 x 30 grid of squares, two triangles each: 1,800 triangles.
    /// let n = 30u32;
    /// let positions = (0..=n)
    ///     .flat_map(|y| (0..=n).map(move |x| [f64::from(x), f64::from(y), 0.0]))
    ///     .collect();
    /// let at = |x: u32, y: u32| y * (n + 1) + x;
    /// let triangles = (0..n)
    ///     .flat_map(|y| (0..n).flat_map(move |x| {
    ///         [[at(x, y), at(x + 1, y), at(x + 1, y + 1)], [at(x, y), at(x + 1, y + 1), at(x, y + 1)]]
    ///     }))
    ///     .collect();
    /// let mesh = IndexedMesh::new(positions, triangles);
    /// let out = simplify(&mesh, &SimplifyOptions::CLUSTER.with_target(Target::Triangles(200)))?;
    /// assert!(out.mesh.triangle_count().abs_diff(200) <= 10);
    /// # Ok::<(), qem_mesh::simplify::SimplifyError>(())
    /// ```
    pub const CLUSTER: SimplifyOptions = SimplifyOptions::DEFAULT.with_method(Method::Clustering);

    /// Sets [`target`](Self::target).
    pub fn with_target(mut self, target: Target) -> Self {
        self.target = target;
        self
    }

    /// Sets [`max_error`](Self::max_error).
    pub fn with_max_error(mut self, max_error: Option<Length>) -> Self {
        self.max_error = max_error;
        self
    }

    /// Sets [`pair_threshold`](Self::pair_threshold).
    pub fn with_pair_threshold(mut self, threshold: Length) -> Self {
        self.pair_threshold = threshold;
        self
    }

    /// Sets [`max_virtual_pairs_per_vertex`](Self::max_virtual_pairs_per_vertex).
    pub fn with_max_virtual_pairs_per_vertex(mut self, k: usize) -> Self {
        self.max_virtual_pairs_per_vertex = k;
        self
    }

    /// Sets [`virtual_pairs`](Self::virtual_pairs).
    pub fn with_virtual_pairs(mut self, which: VirtualPairs) -> Self {
        self.virtual_pairs = which;
        self
    }

    /// Sets [`placement`](Self::placement).
    pub fn with_placement(mut self, placement: PlacementMode) -> Self {
        self.placement = placement;
        self
    }

    /// Sets [`weighting`](Self::weighting).
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets [`quadrics`](Self::quadrics).
    pub fn with_quadrics(mut self, mode: QuadricMode) -> Self {
        self.quadrics = mode;
        self
    }

    /// Sets [`boundary`](Self::boundary).
    pub fn with_boundary(mut self, mode: BoundaryMode) -> Self {
        self.boundary = mode;
        self
    }

    /// Sets [`max_normal_angle`](Self::max_normal_angle) (degrees).
    pub fn with_max_normal_angle(mut self, degrees: f64) -> Self {
        self.max_normal_angle = degrees;
        self
    }

    /// Sets [`min_triangle_quality`](Self::min_triangle_quality).
    pub fn with_min_triangle_quality(mut self, quality: f64) -> Self {
        self.min_triangle_quality = quality;
        self
    }

    /// Sets [`attribute_weights`](Self::attribute_weights).
    pub fn with_attribute_weights(mut self, weights: AttributeWeights) -> Self {
        self.attribute_weights = weights;
        self
    }

    /// Sets [`orientation_check`](Self::orientation_check).
    pub fn with_orientation_check(mut self, on: bool) -> Self {
        self.orientation_check = on;
        self
    }

    /// Sets [`preserve_topology`](Self::preserve_topology).
    pub fn with_preserve_topology(mut self, on: bool) -> Self {
        self.preserve_topology = on;
        self
    }

    /// Sets [`locked_vertices`](Self::locked_vertices).
    pub fn with_locked_vertices(mut self, vertices: Vec<u32>) -> Self {
        self.locked_vertices = vertices;
        self
    }

    /// Sets [`order`](Self::order).
    pub fn with_order(mut self, order: ContractionOrder) -> Self {
        self.order = order;
        self
    }

    /// Sets [`clean`](Self::clean).
    pub fn with_clean(mut self, clean: CleanOptions) -> Self {
        self.clean = clean;
        self
    }

    /// Sets [`strict`](Self::strict).
    pub fn with_strict(mut self, on: bool) -> Self {
        self.strict = on;
        self
    }

    /// Sets [`method`](Self::method). (A `const fn`, so that
    /// [`CLUSTER`](Self::CLUSTER) is spelled from [`DEFAULT`](Self::DEFAULT).)
    pub const fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ratio_asks_for_the_nearest_count_and_never_for_none() {
        // 585.6 and 58.56 asked: the nearest counts.
        assert_eq!(Target::Ratio(0.1).triangles_for(5856), 586);
        assert_eq!(Target::Ratio(0.01).triangles_for(5856), 59);
        assert_eq!(Target::Ratio(0.01).triangles_for(3427), 34);
        // 0.4 asked of a 40-triangle mesh: the last triangle, which the engine keeps.
        assert_eq!(Target::Ratio(0.01).triangles_for(40), 1);
        assert_eq!(Target::Ratio(0.0).triangles_for(40), 1);
        assert_eq!(Target::Ratio(2.0).triangles_for(40), 40);
        assert_eq!(Target::Ratio(0.5).triangles_for(0), 0);
        assert_eq!(Target::Triangles(0).triangles_for(40), 0);
        assert_eq!(Target::None.triangles_for(40), 0);
    }
}
