//! Tests of [`super`]: hand calculations, the thesis's §4.1.1 statements, convergence, bad input.

use super::*;

/// Li & Sundén Table D.1's reference geometry with a profile.
fn table_d1(profile: Profile) -> Design {
    Design {
        pump_exit_radius_m: 0.12,
        turbine_exit_radius_m: 0.065,
        stator_exit_radius_m: 0.06,
        profile,
        pump: BladeAngles { inlet_deg: -50.0, exit_deg: -20.0 },
        turbine: BladeAngles { inlet_deg: 55.0, exit_deg: -50.0 },
        stator: BladeAngles { inlet_deg: 15.0, exit_deg: 60.0 },
        flow_area_m2: 0.01,
        fluid_density_kg_m3: 840.0,
    }
}

fn geo(d: &Design) -> DesignGeometry {
    design_geometry(d, DEFAULT_POINTS).expect("a valid design")
}

fn elements(g: &DesignGeometry) -> [ElementGeometry; 3] {
    [g.pump, g.turbine, g.stator]
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn squash_zero_is_the_circle() {
    let (c, e) = (geo(&table_d1(Profile::Circular)), geo(&table_d1(Profile::Elliptic { squash_ratio: 0.0 })));
    for (x, y) in elements(&c).iter().zip(elements(&e).iter()) {
        for (u, v) in [
            (x.shape_effect_m2, y.shape_effect_m2),
            (x.axial_integral_shape_effect_m2, y.axial_integral_shape_effect_m2),
            (x.axial_extent_m, y.axial_extent_m),
            (x.arc_shape_effect_m2, y.arc_shape_effect_m2),
            (x.fluid_inertia_kg_m2, y.fluid_inertia_kg_m2),
            (x.fluid_length_m, y.fluid_length_m),
            (x.axial_length_m, y.axial_length_m),
        ] {
            assert!(close(u, v, 1e-14), "{u} vs {v}");
        }
    }
    assert!(close(c.fluid_length_m, e.fluid_length_m, 1e-14));
}

/// The circular torus of Table D.1 gives the numbers of the earlier arc estimate (the bundled
/// converter's `[geometry]` before issue 15) where the definitions agree: the arc shape effects, L_f
/// and the fluid inertias.
#[test]
fn circle_reproduces_the_arc_estimate() {
    let g = geo(&table_d1(Profile::Circular));
    assert!((g.pump.arc_shape_effect_m2 - -0.00569).abs() < 5e-6);
    assert!((g.turbine.arc_shape_effect_m2 - 0.00134).abs() < 5e-6);
    assert!((g.stator.arc_shape_effect_m2 - 0.00090).abs() < 5e-6);
    assert!((g.fluid_length_m - 0.2914).abs() < 5e-5);
    assert!((g.pump.fluid_inertia_kg_m2 - 0.0068).abs() < 5e-5);
    assert!((g.turbine.fluid_inertia_kg_m2 - 0.0062).abs() < 5e-5);
    assert!((g.stator.fluid_inertia_kg_m2 - 0.00056).abs() < 5e-6);
    // the axial projection of each half circle is travelled out and back: twice the extent a
    assert!(close(g.pump.axial_length_m, 0.06, 1e-9) && close(g.pump.axial_extent_m, 0.03, 1e-9));
    assert!(close(g.path_length_m, PI * 0.06, 1e-12));
    assert!(close(g.fluid_mass_kg, 840.0 * 0.01 * PI * 0.06, 1e-12));
}

/// The rectangular torus of the hand calculations: (R_s, R_t, R_p, axial width w), m.
const RECTANGLE: (f64, f64, f64, f64) = (0.06, 0.07, 0.12, 0.02);

/// Table D.1's angles on the [`RECTANGLE`] polyline: the pump runs axially at R_s, out to R_p and
/// back; the turbine mirrors it down to R_t; the stator is radial.
fn rectangular_torus() -> Design {
    let (rs, rt, rp, w) = RECTANGLE;
    let profile = Profile::Polyline {
        pump: vec![[rs, 0.0], [rs, w], [rp, w], [rp, 0.0]],
        turbine: vec![[rp, 0.0], [rp, -w], [rt, -w], [rt, 0.0]],
        stator: vec![[rt, 0.0], [rs, 0.0]],
    };
    let mut d = table_d1(profile);
    d.turbine_exit_radius_m = rt;
    d
}

/// A rectangular torus of axial width w: the pump climbs the inner wall at R_s, crosses radially to
/// R_p and comes back at R_p; the turbine mirrors it down to R_t, the stator is radial. The axial
/// projection of pump and turbine is w long, the stator's 0. By hand, the thesis's literal reading
/// (exit radius × |tan(exit angle)| × axial length, whatever the inlet angles):
/// S_p = R_p·|tan α_p,exit|·w, S_t = R_t·|tan α_t,exit|·w, S_s = 0. Positive although Table D.1's
/// pump and turbine exit angles are negative: the sign convention of docs/design.md.
#[test]
fn hand_calculation_pins_the_signs() {
    let (_, rt, rp, w) = RECTANGLE;
    let d = rectangular_torus();
    // Table D.1's angles: the turbine's inlet (+55°) and exit (−50°) have opposite signs
    let g = geo(&d);
    let tan = |deg: f64| deg.to_radians().tan();
    let (sp, st) = (rp * tan(20.0) * w, rt * tan(50.0) * w);
    assert!(close(g.pump.shape_effect_m2, sp, 1e-12), "{}", g.pump.shape_effect_m2);
    assert!(close(g.turbine.shape_effect_m2, st, 1e-12), "{}", g.turbine.shape_effect_m2);
    assert!((sp - 0.000873).abs() < 1e-6 && (st - 0.001668).abs() < 1e-6);
    assert_eq!(g.stator.shape_effect_m2, 0.0);
    assert!(g.pump.shape_effect_m2 > 0.0 && g.turbine.shape_effect_m2 > 0.0);
    // the sign of the exit angle does not enter: mirrored blades give the same shape effects
    let mut mirrored = d.clone();
    for a in [&mut mirrored.pump, &mut mirrored.turbine, &mut mirrored.stator] {
        *a = BladeAngles { inlet_deg: -a.inlet_deg, exit_deg: -a.exit_deg };
    }
    let m = geo(&mirrored);
    assert_eq!(
        (m.pump.shape_effect_m2, m.turbine.shape_effect_m2),
        (g.pump.shape_effect_m2, g.turbine.shape_effect_m2)
    );
    // while the signed comparison readings change sign with the blades
    assert!(close(m.turbine.arc_shape_effect_m2, -g.turbine.arc_shape_effect_m2, 1e-12));
    assert!(close(g.pump.axial_extent_m, w, 1e-12) && close(g.turbine.axial_extent_m, w, 1e-12));
}

/// The comparison readings on the rectangular torus with constant angles: over |dz| with R varying,
/// S_p = (R_s + R_p)·w·tan α_p, S_t = (R_p + R_t)·w·tan α_t, S_s = 0; along the arc
/// S_p = tan α_p·(R_s·w + (R_p² − R_s²)/2 + R_p·w).
#[test]
fn hand_calculation_of_the_comparison_readings() {
    let (rs, rt, rp, w) = RECTANGLE;
    let mut d = rectangular_torus();
    d.pump = BladeAngles { inlet_deg: -30.0, exit_deg: -30.0 };
    d.turbine = BladeAngles { inlet_deg: 45.0, exit_deg: 45.0 };
    d.stator = BladeAngles { inlet_deg: 60.0, exit_deg: 60.0 };
    let g = geo(&d);
    let (tp, tt) = ((-30f64).to_radians().tan(), 1.0);
    assert!(close(g.pump.axial_integral_shape_effect_m2, (rs + rp) * w * tp, 1e-12));
    assert!(close(g.turbine.axial_integral_shape_effect_m2, (rp + rt) * w * tt, 1e-12));
    assert_eq!(g.stator.axial_integral_shape_effect_m2, 0.0);
    assert!(close(g.pump.shape_effect_m2, rp * w * tp.abs(), 1e-12) && close(g.turbine.shape_effect_m2, rt * w, 1e-12));
    assert!(close(g.pump.arc_shape_effect_m2, tp * (rs * w + 0.5 * (rp * rp - rs * rs) + rp * w), 1e-12));
    assert!(close(g.pump.axial_length_m, 2.0 * w, 1e-12) && close(g.stator.axial_length_m, 0.0, 1e-12));
    let rho_a = 8.4;
    let inertia = rho_a * (rs * rs * w + (rp.powi(3) - rs.powi(3)) / 3.0 + rp * rp * w);
    assert!(close(g.pump.fluid_inertia_kg_m2, inertia, 1e-6));
    assert!(close(g.pump.fluid_length_m, (1.0 + tp * tp) * (2.0 * w + rp - rs), 1e-12));
}

/// Table D.1 as a circle: S = R_exit·|tan α_exit|·a with the half-circle's axial extent a = 0.03 m.
/// The turbine's exit angle (−50°) and the integral readings' sign (its inlet part, +55°, dominates)
/// differ (issue 15's "flips the sign"); the literal reading takes the magnitude of the exit term.
#[test]
fn table_d1_literal_reading_by_hand() {
    let g = geo(&table_d1(Profile::Circular));
    let tan = |deg: f64| deg.to_radians().tan();
    assert!(close(g.pump.shape_effect_m2, 0.12 * tan(20.0) * 0.03, 1e-12));
    assert!(close(g.turbine.shape_effect_m2, 0.065 * tan(50.0) * 0.03, 1e-12));
    let stator_extent = 0.03 * (1.0 - (0.025f64 / 0.03).powi(2)).sqrt();
    assert!(close(g.stator.axial_extent_m, stator_extent, 1e-12));
    assert!(close(g.stator.shape_effect_m2, 0.06 * tan(60.0) * stator_extent, 1e-12));
    assert!((g.turbine.shape_effect_m2 - 0.002324).abs() < 1e-6);
    assert!(g.pump.arc_shape_effect_m2 < 0.0 && g.turbine.arc_shape_effect_m2 > 0.0);
    assert!(g.turbine.axial_integral_shape_effect_m2 > 0.0);
}

/// §4.1.1: "a smaller diameter (smaller exit radii), axially thinner (shorter length of the axial
/// projection) converter with less aggressive flow redirection (lower blade exit angles)" has a
/// smaller shape effect.
#[test]
fn thesis_section_4_1_1_trends() {
    let s = |d: &Design| {
        let g = geo(d);
        (g.pump.shape_effect_m2, g.turbine.shape_effect_m2)
    };
    let base = table_d1(Profile::Elliptic { squash_ratio: 0.2 });
    let (sp, st) = s(&base);
    // smaller exit radii: the whole converter scaled down by 10 %
    let mut small = base.clone();
    small.pump_exit_radius_m *= 0.9;
    small.turbine_exit_radius_m *= 0.9;
    small.stator_exit_radius_m *= 0.9;
    let (a, b) = s(&small);
    assert!(a < sp && b < st && close(a, 0.81 * sp, 1e-9));
    // a smaller pump exit radius alone
    let mut rp = base.clone();
    rp.pump_exit_radius_m = 0.11;
    assert!(s(&rp).0 < sp && s(&rp).1 < st);
    // axially thinner: squash 0.2 -> 0.35 -> 0.5
    let mut last = (sp, st);
    for q in [0.35, 0.5] {
        let (a, b) = s(&table_d1(Profile::Elliptic { squash_ratio: q }));
        assert!(a < last.0 && b < last.1, "squash {q}");
        last = (a, b);
    }
    // lower exit angles: the pump's, and the turbine's with Table D.1's inlet angle (only the exit
    // angle enters the literal reading)
    let mut lo = base.clone();
    lo.pump.exit_deg = -10.0;
    assert!(s(&lo).0 < sp && s(&lo).1 == st);
    let mut t = base.clone();
    t.turbine.exit_deg = -40.0;
    assert!(s(&t).1 < st && s(&t).0 == sp);
    // the stator too: exit radius, axial thinness and exit angle
    let ss = |d: &Design| geo(d).stator.shape_effect_m2;
    let mut sa = base.clone();
    sa.stator.exit_deg = 45.0;
    assert!(ss(&sa) < ss(&base));
    assert!(ss(&table_d1(Profile::Elliptic { squash_ratio: 0.35 })) < ss(&base));
}

#[test]
fn converges_with_the_number_of_points() {
    for profile in [Profile::Circular, Profile::Elliptic { squash_ratio: 0.35 }] {
        let d = table_d1(profile);
        let at = |n| design_geometry(&d, n).unwrap();
        let (coarse, mid, fine) = (at(101), at(1001), at(100_001));
        for k in 0..3 {
            let f = |g: &DesignGeometry| elements(g)[k].axial_integral_shape_effect_m2;
            let (e1, e2) = ((f(&coarse) - f(&fine)).abs(), (f(&mid) - f(&fine)).abs());
            // second order: ten times the nodes, about a hundredth of the error
            assert!(e2 < 0.02 * e1 + 1e-15, "element {k}: {e1} then {e2}");
            let e = (f(&at(DEFAULT_POINTS)) - f(&fine)).abs();
            assert!(e < 1e-6 * f(&fine).abs(), "element {k}: {e}");
        }
        assert!(close(at(DEFAULT_POINTS).fluid_length_m, fine.fluid_length_m, 1e-6));
        // the literal reading takes the exact axial extent: no integration error at all
        for k in 0..3 {
            let f = |g: &DesignGeometry| elements(g)[k].shape_effect_m2;
            assert!(close(f(&at(16)), f(&fine), 1e-12), "element {k}");
        }
    }
}

/// The variable-integrand axial reading keeps the mass-matrix bound of the arc reading (physics
/// notes §4): with `|dz| ≤ dl`, `ρ²S_x² / I_x,fluid ≤ (ρ/A)∫_x tan²α dl`. The literal reading has no
/// such bound (docs/design.md): the metal inertias carry it.
#[test]
fn axial_integral_shape_effect_keeps_the_mass_matrix_bound() {
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..200 {
        let mut d = table_d1(Profile::Elliptic { squash_ratio: 0.8 * next() });
        for a in [&mut d.pump, &mut d.turbine, &mut d.stator] {
            *a = BladeAngles { inlet_deg: 170.0 * next() - 85.0, exit_deg: 170.0 * next() - 85.0 };
        }
        let g = geo(&d);
        let (rho, area) = (d.fluid_density_kg_m3, d.flow_area_m2);
        for e in elements(&g) {
            let lhs = rho * rho * e.axial_integral_shape_effect_m2.powi(2) / e.fluid_inertia_kg_m2;
            let rhs = rho / area * (e.fluid_length_m - e.path_length_m);
            assert!(lhs <= rhs * (1.0 + 1e-9), "{lhs} > {rhs}");
        }
    }
}

#[test]
fn batch_equals_one_by_one() {
    let designs: Vec<Design> = (0..7).map(|i| table_d1(Profile::Elliptic { squash_ratio: 0.1 * i as f64 })).collect();
    let mut bad = designs.clone();
    bad[3].flow_area_m2 = -1.0;
    let out = design_geometries(&bad, 301, 2);
    assert_eq!(out.len(), 7);
    for (i, (d, r)) in bad.iter().zip(&out).enumerate() {
        assert_eq!(r, &design_geometry(d, 301), "design {i}");
    }
    assert!(out[3].is_err() && out[4].is_ok());
    assert!(design_geometries(&[], 301, 2).is_empty());
}

fn field_of(d: &Design) -> String {
    design_geometry(d, DEFAULT_POINTS).expect_err("bad input").field
}

#[test]
fn bad_input_names_the_field() {
    let base = table_d1(Profile::Circular);
    let with = |f: &dyn Fn(&mut Design)| {
        let mut d = base.clone();
        f(&mut d);
        field_of(&d)
    };
    assert_eq!(with(&|d| d.pump_exit_radius_m = f64::NAN), "pump_exit_radius_m");
    assert_eq!(with(&|d| d.stator_exit_radius_m = 0.13), "stator_exit_radius_m");
    assert_eq!(with(&|d| d.stator_exit_radius_m = 0.12), "stator_exit_radius_m");
    assert_eq!(with(&|d| d.turbine_exit_radius_m = 0.05), "turbine_exit_radius_m");
    assert_eq!(with(&|d| d.turbine.exit_deg = 90.0), "turbine_exit_angle_deg");
    assert_eq!(with(&|d| d.stator.inlet_deg = f64::INFINITY), "stator_inlet_angle_deg");
    assert_eq!(with(&|d| d.fluid_density_kg_m3 = 0.0), "fluid_density_kg_m3");
    assert_eq!(with(&|d| d.flow_area_m2 = 1e308), "flow_area_m2");
    for s in [-0.1, 1.0, f64::NAN] {
        assert_eq!(with(&|d| d.profile = Profile::Elliptic { squash_ratio: s }), "squash_ratio");
    }
    let e = design_geometry(&base, 3).unwrap_err();
    assert_eq!((e.field.as_str(), e.source), ("points", InputSource::Options));
    let e = design_geometry(&table_d1(Profile::Elliptic { squash_ratio: 1.0 }), 301).unwrap_err();
    assert_eq!(
        e.to_string(),
        "squash_ratio = 1: expected a squash ratio in [0, 1): 1 − axial width / radial height of the torus"
    );
}

/// The three elements' paths of a polyline profile.
type Paths = [Vec<[f64; 2]>; 3];

fn square(rs: f64, rt: f64, rp: f64) -> Paths {
    [
        vec![[rs, 0.0], [rs, 0.02], [rp, 0.02], [rp, 0.0]],
        vec![[rp, 0.0], [rp, -0.02], [rt, -0.02], [rt, 0.0]],
        vec![[rt, 0.0], [rs, 0.0]],
    ]
}

#[test]
fn bad_polylines_name_the_point() {
    let run = |edit: &dyn Fn(&mut Paths)| {
        let mut p = square(0.06, 0.065, 0.12);
        edit(&mut p);
        let [pump, turbine, stator] = p;
        design_geometry(&table_d1(Profile::Polyline { pump, turbine, stator }), 301)
    };
    assert!(run(&|_| ()).is_ok());
    let field = |edit: &dyn Fn(&mut Paths)| run(edit).unwrap_err().field;
    // not closed
    assert_eq!(field(&|p| p[2][1] = [0.061, 0.0]), "pump_path_m[0]");
    assert_eq!(field(&|p| p[1][0] = [0.12, 0.001]), "turbine_path_m[0]");
    // not through the design's radii
    let moved = |p: &mut Paths| {
        p[1][3] = [0.07, 0.0];
        p[2][0] = [0.07, 0.0];
    };
    assert_eq!(field(&moved), "turbine_path_m[3] r");
    // not ordered: the pump turning inwards, the turbine outwards (both within [R_s, R_p])
    assert_eq!(field(&|p| p[0].insert(3, [0.10, 0.01])), "pump_path_m[3]");
    assert_eq!(field(&|p| p[1].insert(3, [0.09, -0.01])), "turbine_path_m[3]");
    // a point outside [R_s, R_p]
    assert_eq!(field(&|p| p[0][2] = [0.05, 0.02]), "pump_path_m[2]");
    assert_eq!(field(&|p| p[1].insert(2, [0.13, -0.02])), "turbine_path_m[2]");
    assert_eq!(field(&|p| p[2].insert(1, [0.05, 0.0])), "stator_path_m[1]");
    let e = run(&|p| p[0].insert(3, [0.10, 0.01])).unwrap_err();
    assert_eq!(e.expected, "a radius not below the point before's (the flow order)");
    // too short, not finite, repeated points
    assert_eq!(field(&|p| p[2].truncate(1)), "stator_path_m");
    assert_eq!(field(&|p| p[0][1] = [0.06, f64::NAN]), "pump_path_m[1]");
    assert_eq!(field(&|p| p[0].insert(1, [0.06, 0.0])), "pump_path_m[1]");
    let e = run(&|p| p[2][1] = [0.061, 0.0]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "pump_path_m[0] = (0.06, 0): expected the last point of stator_path_m, (0.061, 0) (a closed path, to 1 µm)"
    );
}

#[test]
fn profiles_by_name_and_columns() {
    assert_eq!(Profile::from_parts("circular", None, None), Ok(Profile::Circular));
    assert_eq!(Profile::from_parts("elliptic", Some(0.2), None), Ok(Profile::Elliptic { squash_ratio: 0.2 }));
    let field = |k, s, p| Profile::from_parts(k, s, p).unwrap_err().field;
    assert_eq!(field("oval", None, None), "profile");
    assert_eq!(field("elliptic", None, None), "squash_ratio");
    assert_eq!(field("circular", Some(0.1), None), "squash_ratio");
    assert_eq!(field("polyline", None, None), "pump_path_m");
    assert_eq!(field("elliptic", Some(0.1), Some(square(0.06, 0.065, 0.12))), "pump_path_m");
    let g = geo(&table_d1(Profile::Circular));
    let (names, values) = (geometry_columns(), g.values());
    assert_eq!((names.len(), values.len()), (30, 30));
    assert_eq!((names[0].as_str(), values[0]), ("pump_shape_effect_m2", g.pump.shape_effect_m2));
    let integral = g.pump.axial_integral_shape_effect_m2;
    assert_eq!((names[1].as_str(), values[1]), ("pump_axial_integral_shape_effect_m2", integral));
    assert_eq!((names[26].as_str(), values[26]), ("stator_fluid_inertia_kg_m2", g.stator.fluid_inertia_kg_m2));
    assert_eq!((names[27].as_str(), values[27]), ("fluid_length_m", g.fluid_length_m));
}
