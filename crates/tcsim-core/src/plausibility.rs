//! Physical plausibility ranges: the values that the torque converters of cars and trucks, their
//! fluids and their measurements take.
//!
//! A value outside its range is not impossible but suspicious: most often a unit mistake (rpm in a
//! rad/s column, milliseconds in a `time_s` column) or a typo. The callers decide what follows:
//! a warning for a converter's design values, a refusal that the user can override for measured
//! and commanded values (the command line's `--allow-implausible`). Values that make the numbers
//! non-finite are refused whatever the ranges say; that is not this module's concern.
//!
//! This table is the one owner of the ranges: the Python layer reads it through
//! `tcsim._core.plausibility_ranges()` and `docs/guarantees.md` lists it.

/// One quantity's plausible range, closed at both ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// The quantity's name, with its unit as in the file conventions (`speed_rad_s`).
    pub quantity: &'static str,
    /// The unit, as printed in messages (`rad/s`).
    pub unit: &'static str,
    /// The smallest plausible value.
    pub low: f64,
    /// The largest plausible value.
    pub high: f64,
    /// Why the range is what it is, in a few words (shown in messages and in the docs).
    pub why: &'static str,
}

impl PlausibleRange {
    /// Whether `value` lies in the range (NaN does not).
    pub fn contains(&self, value: f64) -> bool {
        (self.low..=self.high).contains(&value)
    }
}

/// Every range, in the order the docs list them.
pub const RANGES: &[PlausibleRange] = &[
    PlausibleRange {
        quantity: "speed_rad_s",
        unit: "rad/s",
        low: -1100.0,
        high: 1100.0,
        why: "shaft speeds within ±10 500 rpm; engines redline below 9 000 rpm",
    },
    PlausibleRange {
        quantity: "flow_m3_s",
        unit: "m³/s",
        low: -20.0,
        high: 20.0,
        why: "torus through-flow of converters up to 1 m across at up to 10 500 rpm (0.08 m³/s at stall and 2000 rpm for the thesis's)",
    },
    PlausibleRange {
        quantity: "torque_nm",
        unit: "N·m",
        low: -10_000.0,
        high: 10_000.0,
        why: "shaft torques of car and truck converters, stall torque included",
    },
    PlausibleRange {
        quantity: "sample_spacing_s",
        unit: "s",
        low: 1e-6,
        high: 0.1,
        why: "median time step of a measurement logged at 10 Hz to 1 MHz; milliseconds read as seconds give more",
    },
    PlausibleRange {
        quantity: "scenario_duration_s",
        unit: "s",
        low: 0.1,
        high: 3600.0,
        why: "pedal scenarios from a tip-in to an hour-long drive cycle (WLTC: 1800 s); a time_ms column read as \
              seconds gives more, seconds read as milliseconds less",
    },
    PlausibleRange {
        quantity: "trace_acceleration_m_s2",
        unit: "m/s²",
        low: -10.0,
        high: 5.0,
        why: "a drive trace's speed change over a second: published cycles stay below 4 m/s² (US06: 3.8), \
              0–100 km/h in 5.5 s is 5, braking at 1 g 10; a trace in km/h read as m/s has 3.6 times its \
              own (UDDS's 1.48 m/s² reads as 5.3)",
    },
    PlausibleRange {
        quantity: "torque_ratio",
        unit: "",
        low: 0.0,
        high: 10.0,
        why: "torque ratios of hydrodynamic converters; stall torque ratios are 1.5 to 3.5",
    },
    PlausibleRange {
        quantity: "radius_m",
        unit: "m",
        low: 0.02,
        high: 0.5,
        why: "blade radii of converters up to 1 m across",
    },
    PlausibleRange {
        quantity: "blade_angle_deg",
        unit: "deg",
        low: -85.0,
        high: 85.0,
        why: "blade angles; at ±90° a blade lies across the flow and its tangent diverges",
    },
    PlausibleRange {
        quantity: "fluid_density_kg_m3",
        unit: "kg/m³",
        low: 600.0,
        high: 1200.0,
        why: "automatic transmission fluids are 820–880 kg/m³",
    },
    PlausibleRange {
        quantity: "flow_area_m2",
        unit: "m²",
        low: 1e-4,
        high: 0.1,
        why: "through-flow areas of converters up to 1 m across",
    },
    PlausibleRange {
        quantity: "fluid_length_m",
        unit: "m",
        low: 0.02,
        high: 2.0,
        why: "length of the fluid path round the torus",
    },
    PlausibleRange {
        quantity: "inertia_kg_m2",
        unit: "kg·m²",
        low: 1e-4,
        high: 10.0,
        why: "pump, turbine and stator inertias with their fluid",
    },
    PlausibleRange {
        quantity: "loss_coefficient",
        unit: "",
        low: 0.0,
        high: 10.0,
        why: "shock and friction loss coefficients (the thesis uses 0.2–1)",
    },
];

/// The range of `quantity`, if it has one.
pub fn range(quantity: &str) -> Option<&'static PlausibleRange> {
    RANGES.iter().find(|r| r.quantity == quantity)
}

/// Of `values` (`(value, quantity)`), the index of the one farthest outside its range, measured
/// as the factor by which it misses the range (its magnitude for a range that contains zero):
/// the value to blame when their combination makes a model's numbers non-finite. None when every
/// value is inside.
pub fn farthest_outside(values: &[(f64, &str)]) -> Option<usize> {
    let miss = |v: f64, q: &str| -> f64 {
        let Some(r) = range(q) else { return 0.0 };
        if r.contains(v) {
            return 0.0;
        }
        if !v.is_finite() {
            return f64::INFINITY;
        }
        let (lo, hi, a) = (r.low.abs().max(f64::MIN_POSITIVE), r.high.abs().max(f64::MIN_POSITIVE), v.abs());
        if r.low > 0.0 && v > 0.0 && v < r.low {
            (lo / a).ln()
        } else if v > r.high {
            (a / hi).ln().max(f64::MIN_POSITIVE)
        } else {
            (a / lo).ln().max(f64::MIN_POSITIVE)
        }
    };
    let (i, m) = values.iter().enumerate().map(|(i, &(v, q))| (i, miss(v, q))).max_by(|a, b| a.1.total_cmp(&b.1))?;
    (m > 0.0).then_some(i)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_farthest_value_is_blamed() {
        let v = [(840.0, "fluid_density_kg_m3"), (8.4e-292, "fluid_density_kg_m3"), (1e6, "radius_m")];
        assert_eq!(super::farthest_outside(&v), Some(1));
        assert_eq!(super::farthest_outside(&v[..1]), None);
        assert_eq!(super::farthest_outside(&[(0.12, "radius_m"), (1e6, "radius_m")]), Some(1));
    }

    use super::*;

    #[test]
    fn every_range_is_ordered_finite_and_named_once() {
        for (i, r) in RANGES.iter().enumerate() {
            assert!(r.low.is_finite() && r.high.is_finite() && r.low < r.high, "{r:?}");
            assert!(RANGES[..i].iter().all(|o| o.quantity != r.quantity), "{} twice", r.quantity);
            assert_eq!(range(r.quantity), Some(r));
        }
        assert_eq!(range("no_such_quantity"), None);
    }

    #[test]
    fn the_bundled_converter_is_plausible_and_unit_mistakes_are_not() {
        let speed = range("speed_rad_s").unwrap();
        assert!(speed.contains(2000.0 * std::f64::consts::PI / 30.0));
        assert!(!speed.contains(6000.0), "6000 rpm written in a rad/s column");
        assert!(!speed.contains(f64::NAN));
        let density = range("fluid_density_kg_m3").unwrap();
        assert!(density.contains(840.0) && !density.contains(8.4e-292));
        let spacing = range("sample_spacing_s").unwrap();
        assert!(spacing.contains(0.01) && !spacing.contains(10.0), "10 ms logged as 10 s");
        assert!(!spacing.contains(1.0), "1 kHz logged in milliseconds");
        let duration = range("scenario_duration_s").unwrap();
        assert!(duration.contains(30.0) && duration.contains(1800.0) && !duration.contains(30_000.0));
        let angle = range("blade_angle_deg").unwrap();
        assert!(angle.contains(-50.0) && angle.contains(60.0) && !angle.contains(89.999999999));
    }
}
