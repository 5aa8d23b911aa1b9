//! The geometry of a converter design: the torus's mean meridional streamline and the blades, and
//! what the Hrovat & Tobler model needs from them (Li & Sundén 2016 §2.2.2, eqs 2.12–2.18, §4.1.1
//! fig. 4.7, Appendix B). `docs/design.md` documents every formula and its source.
//!
//! The mean streamline lies in the meridional plane (`r` from the converter's axis, `z` along it).
//! It runs through the pump from the pump inlet (= stator exit, radius `R_s`, Appendix D's
//! `stator_exit_radius_m`) out to the pump exit (`R_p`, `pump_exit_radius_m`), through the turbine
//! in to the turbine exit (`R_t`, `turbine_exit_radius_m`) and through the stator back to `R_s`.
//! Profiles ([`Profile`]):
//!
//! * circular: a circle whose innermost point is at `R_s` and outermost at `R_p`;
//! * elliptic: the same radial extent, axial extent `(1 − squash)·(R_p − R_s)` (thesis §4.3.2: a
//!   squash ratio of 20 % means "the width of the flow path is 80 % of its height"), squash 0 the
//!   circle;
//! * polyline: the user's meridional path of each element, `(r, z)` vertices in the flow direction.
//!
//! Along each element the blade angle varies linearly with the path length from the inlet to the
//! exit angle (signed as Table D.1). With `g = R·tan α`, per element x:
//!
//! * shape effect, the thesis's literal reading (§4.1.1, eqs 4.1–4.2 and 2.16–2.18, fig. 4.7):
//!   `S_x = R_x,exit · |tan α_x,exit| · L_x`, the element's exit radius and exit blade angle
//!   (constants under the integral) times `L_x`, the length of the axial projection of the element's
//!   path (its axial extent `max z − min z`, the "axial projections of the impeller and turbine
//!   measuring approximately 30-50 mm" of §4.1.1). A magnitude: the thesis's chapter 4 runs eqs
//!   2.12–2.13 with positive shape effects "calculated in accordance with equations 2.16 and 2.17",
//!   and its finding (a larger shape effect, a deeper effective-TR dip; none at S = 0) holds only
//!   with S ≥ 0 (docs/design.md, "Sign convention");
//! * for comparison only, signed as the angles: the variable-integrand axial reading `∫ g |dz|` and
//!   the arc reading `∫ g dl` along the path (the angular momentum of the fluid relative to the blades);
//! * fluid mass `ρ·A·l_x` (`l_x` the path length) and fluid inertia `ρ·A·∫ R² dl`;
//! * the equivalent fluid length `L_f = Σ_x ∫ (1 + tan² α) dl`.
//!
//! The flow area A is given (thesis assumption 2: constant around the path; Table D.1 gives 0.01
//! m²); blade thickness is not taken into account (assumption 4). Integrals are trapezoidal over
//! `points` nodes per element (exact path element for the conics, straight segments for a polyline).

use std::f64::consts::PI;

use crate::error::{sig, CoreError, CoreResult, InputSource};

/// The default number of integration nodes per element.
pub const DEFAULT_POINTS: usize = 2001;
/// The fewest and the most integration nodes per element.
pub const POINTS_RANGE: (usize, usize) = (16, 1_000_000);
/// How far a polyline's end points may lie from the design's radii or from each other, m.
pub const POLYLINE_TOLERANCE_M: f64 = 1e-6;

/// The shape of the mean meridional streamline.
#[derive(Debug, Clone, PartialEq)]
pub enum Profile {
    /// A circle through `R_s` and `R_p`.
    Circular,
    /// An ellipse with radial semi-axis `(R_p − R_s)/2` and axial semi-axis `(1 − squash)` times it.
    Elliptic { squash_ratio: f64 },
    /// The path of each element as `(r, z)` vertices in m, in the flow direction; consecutive
    /// elements share their end points and the stator ends where the pump starts.
    Polyline { pump: Vec<[f64; 2]>, turbine: Vec<[f64; 2]>, stator: Vec<[f64; 2]> },
}

/// Inlet and exit blade angle of one element, degrees, signed as Li & Sundén Table D.1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeAngles {
    pub inlet_deg: f64,
    pub exit_deg: f64,
}

/// A converter design: torus, blades, fluid. Radii as Appendix D names them.
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Pump exit radius `R_p` = outermost radius of the mean streamline, m.
    pub pump_exit_radius_m: f64,
    /// Turbine exit radius `R_t` (= stator inlet), m.
    pub turbine_exit_radius_m: f64,
    /// Stator exit radius `R_s` (= pump inlet) = innermost radius of the mean streamline, m.
    pub stator_exit_radius_m: f64,
    pub profile: Profile,
    pub pump: BladeAngles,
    pub turbine: BladeAngles,
    pub stator: BladeAngles,
    /// Flow area A perpendicular to the through-flow, constant around the path, m².
    pub flow_area_m2: f64,
    pub fluid_density_kg_m3: f64,
}

/// What the design gives for one element.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ElementGeometry {
    /// `S = R_exit · |tan α_exit| · L_axial` (eqs 4.1–4.2 and 2.16–2.18 read with the exit values,
    /// `L_axial` the axial extent), m². A magnitude, as the thesis's chapter 4 uses the shape
    /// effects (docs/design.md, "Sign convention").
    pub shape_effect_m2: f64,
    /// `∫ R tan α |dz|` with R and α varying along the path (comparison only), m².
    pub axial_integral_shape_effect_m2: f64,
    /// `∫ R tan α dl` along the path (the arc reading), m².
    pub arc_shape_effect_m2: f64,
    /// Length of the path `l_x`, m.
    pub path_length_m: f64,
    /// Length of the axial projection `L_x = ∫ |dz|`, m.
    pub axial_length_m: f64,
    /// Axial extent of the element's path, `max z − min z`, m.
    pub axial_extent_m: f64,
    /// `∫ (1 + tan² α) dl`, the element's part of `L_f`, m.
    pub fluid_length_m: f64,
    /// `ρ A l_x`, kg.
    pub fluid_mass_kg: f64,
    /// `ρ A ∫ R² dl`, kg·m².
    pub fluid_inertia_kg_m2: f64,
}

/// What the design gives: per element, and `L_f` and the fluid mass of the whole torus.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DesignGeometry {
    pub pump: ElementGeometry,
    pub turbine: ElementGeometry,
    pub stator: ElementGeometry,
    /// Equivalent fluid length `L_f`, m.
    pub fluid_length_m: f64,
    /// Length of the whole mean streamline, m.
    pub path_length_m: f64,
    /// Fluid mass of the torus `ρ A Σ l_x`, kg.
    pub fluid_mass_kg: f64,
}

/// The names of the profiles ([`Profile`]) in a design's `profile` field.
pub const PROFILE_KINDS: [&str; 3] = ["circular", "elliptic", "polyline"];

impl Profile {
    /// The profile named `kind` ([`PROFILE_KINDS`]); `squash_ratio` belongs to `elliptic` only and
    /// the element paths (pump, turbine, stator) to `polyline` only. The values are checked by
    /// [`check_design`].
    pub fn from_parts(kind: &str, squash_ratio: Option<f64>, paths: Option<[Vec<[f64; 2]>; 3]>) -> CoreResult<Self> {
        match (kind, squash_ratio, paths) {
            ("circular", None, None) => Ok(Profile::Circular),
            ("elliptic", Some(s), None) => Ok(Profile::Elliptic { squash_ratio: s }),
            ("elliptic", None, _) => Err(err("squash_ratio", "missing", "a squash ratio for the elliptic profile")),
            ("polyline", None, Some([pump, turbine, stator])) => Ok(Profile::Polyline { pump, turbine, stator }),
            ("polyline", _, None) => Err(err(
                "pump_path_m",
                "missing",
                "the (r, z) paths of pump, turbine and stator for a polyline profile",
            )),
            ("circular" | "polyline", Some(s), _) => {
                Err(err("squash_ratio", s, "no squash ratio: it belongs to the elliptic profile"))
            }
            ("circular" | "elliptic", _, Some(_)) => {
                Err(err("pump_path_m", "given", "no element paths: they belong to the polyline profile"))
            }
            _ => Err(err("profile", kind, "circular, elliptic or polyline")),
        }
    }
}

/// The quantities of each element in [`DesignGeometry::values`], after the element's name.
pub const ELEMENT_QUANTITIES: [&str; 9] = [
    "shape_effect_m2",
    "axial_integral_shape_effect_m2",
    "arc_shape_effect_m2",
    "path_length_m",
    "axial_length_m",
    "axial_extent_m",
    "fluid_length_m",
    "fluid_mass_kg",
    "fluid_inertia_kg_m2",
];
/// The quantities of the whole torus in [`DesignGeometry::values`], after the elements'.
pub const TORUS_QUANTITIES: [&str; 3] = ["fluid_length_m", "path_length_m", "fluid_mass_kg"];

/// The column names of [`DesignGeometry::values`]: `pump_shape_effect_m2`, …, `stator_fluid_inertia_kg_m2`,
/// then `fluid_length_m`, `path_length_m`, `fluid_mass_kg`.
pub fn geometry_columns() -> Vec<String> {
    let elements = ["pump", "turbine", "stator"].into_iter();
    let per = elements.flat_map(|e| ELEMENT_QUANTITIES.iter().map(move |q| format!("{e}_{q}")));
    per.chain(TORUS_QUANTITIES.iter().map(|q| q.to_string())).collect()
}

impl ElementGeometry {
    fn values(&self) -> [f64; 9] {
        [
            self.shape_effect_m2,
            self.axial_integral_shape_effect_m2,
            self.arc_shape_effect_m2,
            self.path_length_m,
            self.axial_length_m,
            self.axial_extent_m,
            self.fluid_length_m,
            self.fluid_mass_kg,
            self.fluid_inertia_kg_m2,
        ]
    }
}

impl DesignGeometry {
    /// The values in the order of [`geometry_columns`].
    pub fn values(&self) -> Vec<f64> {
        let mut v: Vec<f64> = [self.pump, self.turbine, self.stator].iter().flat_map(|e| e.values()).collect();
        v.extend([self.fluid_length_m, self.path_length_m, self.fluid_mass_kg]);
        v
    }
}

/// Nodes of one element's path: radius, axial position, the path length of each segment, and the
/// exact axial extent of the path (`max z − min z`, m).
struct Path {
    r: Vec<f64>,
    z: Vec<f64>,
    dl: Vec<f64>,
    extent: f64,
}

/// `max z − min z` of `z = b sin t` over `[t0, t1]` (`t0 < t1 ≤ 2π`): the ends and the extrema at
/// `π/2` and `3π/2` where they lie inside.
fn conic_extent(b: f64, t0: f64, t1: f64) -> f64 {
    let mut z = vec![b * t0.sin(), b * t1.sin()];
    for (t, v) in [(0.5 * PI, b), (1.5 * PI, -b)] {
        if t0 < t && t < t1 {
            z.push(v);
        }
    }
    let (lo, hi) = z.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    hi - lo
}

fn err(field: impl Into<String>, value: impl std::fmt::Display, expected: impl Into<String>) -> CoreError {
    CoreError::new(field, value, expected)
}

fn positive(field: &str, v: f64, what: &str) -> CoreResult<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(field, v, format!("a finite, positive {what}")))
    }
}

fn check_angles(name: &str, a: BladeAngles) -> CoreResult<()> {
    for (which, v) in [("inlet", a.inlet_deg), ("exit", a.exit_deg)] {
        if !(v.is_finite() && v.abs() < 90.0) {
            return Err(err(
                format!("{name}_{which}_angle_deg"),
                v,
                "a blade angle strictly between -90 and 90 degrees",
            ));
        }
    }
    Ok(())
}

fn check_scalars(d: &Design) -> CoreResult<()> {
    positive("pump_exit_radius_m", d.pump_exit_radius_m, "radius in m")?;
    positive("turbine_exit_radius_m", d.turbine_exit_radius_m, "radius in m")?;
    positive("stator_exit_radius_m", d.stator_exit_radius_m, "radius in m")?;
    let (rp, rt, rs) = (d.pump_exit_radius_m, d.turbine_exit_radius_m, d.stator_exit_radius_m);
    if rs >= rp {
        return Err(err(
            "stator_exit_radius_m",
            rs,
            format!("less than the pump exit radius {} m (the torus's inner radius below its outer)", sig(rp)),
        ));
    }
    if !(rs < rt && rt < rp) {
        return Err(err(
            "turbine_exit_radius_m",
            rt,
            format!("between the stator exit radius {} m and the pump exit radius {} m", sig(rs), sig(rp)),
        ));
    }
    check_angles("pump", d.pump)?;
    check_angles("turbine", d.turbine)?;
    check_angles("stator", d.stator)?;
    positive("flow_area_m2", d.flow_area_m2, "area in m²")?;
    positive("fluid_density_kg_m3", d.fluid_density_kg_m3, "density in kg/m³")
}

/// Check a design without integrating: every field finite and in range, `R_s < R_t < R_p`, the
/// squash ratio in [0, 1), a polyline closed, through the design's radii and ordered.
pub fn check_design(d: &Design) -> CoreResult<()> {
    check_scalars(d)?;
    match &d.profile {
        Profile::Circular => Ok(()),
        Profile::Elliptic { squash_ratio: s } => {
            if s.is_finite() && (0.0..1.0).contains(s) {
                Ok(())
            } else {
                Err(err("squash_ratio", s, "a squash ratio in [0, 1): 1 − axial width / radial height of the torus"))
            }
        }
        Profile::Polyline { pump, turbine, stator } => check_polyline(d, [pump, turbine, stator]),
    }
}

const ELEMENTS: [&str; 3] = ["pump", "turbine", "stator"];

fn point_text(p: [f64; 2]) -> String {
    format!("({}, {})", sig(p[0]), sig(p[1]))
}

fn check_vertices(name: &str, path: &[[f64; 2]]) -> CoreResult<()> {
    let field = format!("{name}_path_m");
    if path.len() < 2 {
        return Err(err(field, format!("{} points", path.len()), "at least 2 (r, z) points in m"));
    }
    for (i, p) in path.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite() && p[0] > 0.0) {
            return Err(err(format!("{field}[{i}]"), point_text(*p), "a finite (r, z) point in m with r > 0"));
        }
        if i > 0 && (p[0] - path[i - 1][0]).hypot(p[1] - path[i - 1][1]) <= POLYLINE_TOLERANCE_M {
            return Err(err(format!("{field}[{i}]"), point_text(*p), "a point distinct from the one before (1 µm)"));
        }
    }
    Ok(())
}

fn check_polyline(d: &Design, paths: [&Vec<[f64; 2]>; 3]) -> CoreResult<()> {
    for (name, path) in ELEMENTS.iter().zip(paths) {
        check_vertices(name, path)?;
    }
    // closed: each element starts where the one before it ends (the pump where the stator ends)
    for k in 0..3 {
        let (prev, cur) = (paths[(k + 2) % 3], paths[k]);
        let (end, start) = (prev[prev.len() - 1], cur[0]);
        if (end[0] - start[0]).hypot(end[1] - start[1]) > POLYLINE_TOLERANCE_M {
            let expected = format!(
                "the last point of {}_path_m, {} (a closed path, to 1 µm)",
                ELEMENTS[(k + 2) % 3],
                point_text(end)
            );
            return Err(err(format!("{}_path_m[0]", ELEMENTS[k]), point_text(start), expected));
        }
    }
    // through the design's radii: pump inlet R_s, pump exit R_p, turbine exit R_t
    let (np, nt) = (paths[0].len() - 1, paths[1].len() - 1);
    let ends = [
        (String::from("pump_path_m[0]"), paths[0][0][0], "stator_exit_radius_m", d.stator_exit_radius_m),
        (format!("pump_path_m[{np}]"), paths[0][np][0], "pump_exit_radius_m", d.pump_exit_radius_m),
        (format!("turbine_path_m[{nt}]"), paths[1][nt][0], "turbine_exit_radius_m", d.turbine_exit_radius_m),
    ];
    for (field, r, name, want) in ends {
        if (r - want).abs() > POLYLINE_TOLERANCE_M {
            return Err(err(format!("{field} r"), r, format!("the design's {name} {} m (to 1 µm)", sig(want))));
        }
    }
    check_order(paths)
}

/// Ordered: the pump carries the fluid outwards (r never falls along it), the turbine inwards (r
/// never rises), and no point lies outside `[R_s, R_p]` (the pump inlet the innermost, its exit
/// the outermost point).
fn check_order(paths: [&Vec<[f64; 2]>; 3]) -> CoreResult<()> {
    let (rs, rp) = (paths[0][0][0], paths[0][paths[0].len() - 1][0]);
    for (k, (name, path)) in ELEMENTS.iter().zip(paths).enumerate() {
        for (i, w) in path.windows(2).enumerate() {
            let bad_dir = match k {
                0 => w[1][0] < w[0][0],
                1 => w[1][0] > w[0][0],
                _ => false,
            };
            let (r, field) = (w[1][0], format!("{name}_path_m[{}]", i + 1));
            if bad_dir {
                let dir = if k == 0 { "not below" } else { "not above" };
                return Err(err(
                    field,
                    point_text(w[1]),
                    format!("a radius {dir} the point before's (the flow order)"),
                ));
            }
            if r < rs - POLYLINE_TOLERANCE_M || r > rp + POLYLINE_TOLERANCE_M {
                let expected =
                    format!("a radius within the pump inlet's {} m and the pump exit's {} m", sig(rs), sig(rp));
                return Err(err(field, point_text(w[1]), expected));
            }
        }
    }
    Ok(())
}

fn check_points(points: usize) -> CoreResult<()> {
    if (POINTS_RANGE.0..=POINTS_RANGE.1).contains(&points) {
        Ok(())
    } else {
        Err(CoreError::of(
            InputSource::Options,
            "points",
            points,
            format!("{} to {} integration nodes per element", POINTS_RANGE.0, POINTS_RANGE.1),
        ))
    }
}

/// The conic's nodes from parameter `t0` to `t1`: `r = r_c − a cos t`, `z = b sin t`, the path
/// element of each segment by the trapezoidal rule on the speed `√(a² sin² t + b² cos² t)`.
fn conic_path(rc: f64, a: f64, b: f64, t0: f64, t1: f64, n: usize) -> Path {
    let h = (t1 - t0) / (n - 1) as f64;
    let (mut r, mut z, mut dl) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    let mut last_speed = 0.0;
    for i in 0..n {
        let (sin, cos) = (if i + 1 == n { t1 } else { t0 + h * i as f64 }).sin_cos();
        let speed = ((a * sin).powi(2) + (b * cos).powi(2)).sqrt();
        r.push(rc - a * cos);
        z.push(b * sin);
        if i > 0 {
            dl.push(0.5 * (last_speed + speed) * h);
        }
        last_speed = speed;
    }
    Path { r, z, dl, extent: conic_extent(b, t0, t1) }
}

/// A polyline's nodes: each segment cut into pieces in proportion to its share of the length.
fn polyline_path(vertices: &[[f64; 2]], n: usize) -> Path {
    let seg: Vec<f64> = vertices.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).collect();
    let total: f64 = seg.iter().sum();
    let (mut r, mut z, mut dl) = (vec![vertices[0][0]], vec![vertices[0][1]], Vec::with_capacity(n));
    for (w, len) in vertices.windows(2).zip(&seg) {
        let m = ((len / total * (n - 1) as f64).round() as usize).max(1);
        for j in 1..=m {
            let f = j as f64 / m as f64;
            r.push(if j == m { w[1][0] } else { w[0][0] + f * (w[1][0] - w[0][0]) });
            z.push(if j == m { w[1][1] } else { w[0][1] + f * (w[1][1] - w[0][1]) });
            dl.push(len / m as f64);
        }
    }
    let (lo, hi) = z.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v: &f64| (lo.min(v), hi.max(v)));
    Path { r, z, dl, extent: hi - lo }
}

/// The three elements' paths of a checked design.
fn paths(d: &Design, n: usize) -> [Path; 3] {
    let (rp, rt, rs) = (d.pump_exit_radius_m, d.turbine_exit_radius_m, d.stator_exit_radius_m);
    let (rc, a) = (0.5 * (rp + rs), 0.5 * (rp - rs));
    let b = match &d.profile {
        Profile::Circular => a,
        Profile::Elliptic { squash_ratio } => (1.0 - squash_ratio) * a,
        Profile::Polyline { pump, turbine, stator } => {
            return [polyline_path(pump, n), polyline_path(turbine, n), polyline_path(stator, n)]
        }
    };
    // the turbine exit: where the return half (t in (π, 2π)) is back at R_t
    let tt = 2.0 * PI - ((rc - rt) / a).clamp(-1.0, 1.0).acos();
    [conic_path(rc, a, b, 0.0, PI, n), conic_path(rc, a, b, PI, tt, n), conic_path(rc, a, b, tt, 2.0 * PI, n)]
}

/// One element's geometry; `exit_radius_m` is the design's radius at the element's exit.
fn element(p: &Path, angles: BladeAngles, exit_radius_m: f64, rho_a: f64) -> ElementGeometry {
    let length: f64 = p.dl.iter().sum();
    let (a0, a1) = (angles.inlet_deg.to_radians(), angles.exit_deg.to_radians());
    let node = |i: usize, s: f64| {
        let tan = (a0 + (a1 - a0) * (s / length).min(1.0)).tan();
        (p.r[i] * tan, p.r[i] * p.r[i], 1.0 + tan * tan)
    };
    // trapezoidal sums: shape effect over |dz| and along dl, ∫R² dl, ∫(1 + tan²α) dl
    let (mut axial, mut arc, mut r2, mut weight, mut dz_sum) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut s, mut prev) = (0.0, node(0, 0.0));
    for (i, &dl) in p.dl.iter().enumerate() {
        s += dl;
        let cur = node(i + 1, s);
        let dz = (p.z[i + 1] - p.z[i]).abs();
        axial += 0.5 * (prev.0 + cur.0) * dz;
        arc += 0.5 * (prev.0 + cur.0) * dl;
        r2 += 0.5 * (prev.1 + cur.1) * dl;
        weight += 0.5 * (prev.2 + cur.2) * dl;
        dz_sum += dz;
        prev = cur;
    }
    let extent = p.extent;
    ElementGeometry {
        shape_effect_m2: exit_radius_m * a1.tan().abs() * extent,
        axial_integral_shape_effect_m2: axial,
        arc_shape_effect_m2: arc,
        path_length_m: length,
        axial_length_m: dz_sum,
        axial_extent_m: extent,
        fluid_length_m: weight,
        fluid_mass_kg: rho_a * length,
        fluid_inertia_kg_m2: rho_a * r2,
    }
}

/// The geometry of design `d` with `points` integration nodes per element ([`DEFAULT_POINTS`] is a
/// good choice: relative error below 1e-6).
pub fn design_geometry(d: &Design, points: usize) -> CoreResult<DesignGeometry> {
    check_points(points)?;
    check_design(d)?;
    let rho_a = d.fluid_density_kg_m3 * d.flow_area_m2;
    let [p, t, s] = paths(d, points);
    let (pump, turbine, stator) = (
        element(&p, d.pump, d.pump_exit_radius_m, rho_a),
        element(&t, d.turbine, d.turbine_exit_radius_m, rho_a),
        element(&s, d.stator, d.stator_exit_radius_m, rho_a),
    );
    let path = pump.path_length_m + turbine.path_length_m + stator.path_length_m;
    let out = DesignGeometry {
        pump,
        turbine,
        stator,
        fluid_length_m: pump.fluid_length_m + turbine.fluid_length_m + stator.fluid_length_m,
        path_length_m: path,
        fluid_mass_kg: rho_a * path,
    };
    if [out.fluid_length_m, out.fluid_mass_kg, pump.fluid_inertia_kg_m2].iter().all(|x| x.is_finite()) {
        Ok(out)
    } else {
        Err(err("flow_area_m2", d.flow_area_m2, "an area and density whose fluid mass and inertia are finite"))
    }
}

/// [`design_geometry`] of each design, in order, on up to `threads` threads (at least 1).
pub fn design_geometries(designs: &[Design], points: usize, threads: usize) -> Vec<CoreResult<DesignGeometry>> {
    let threads = threads.clamp(1, designs.len().max(1));
    let chunk = designs.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        let handles: Vec<_> = designs
            .chunks(chunk)
            .map(|c| scope.spawn(move || c.iter().map(|d| design_geometry(d, points)).collect::<Vec<_>>()))
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))).collect()
    })
}

#[cfg(test)]
#[path = "design_tests.rs"]
mod tests;
