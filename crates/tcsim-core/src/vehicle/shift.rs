//! Shift control of the automatic gearbox and the gearbox's inertia during a shift.
//!
//! * **Inertia during a shift.** In gear k the gearbox's rotating parts are lumped into
//!   `input_inertia_kg_m2[k]` = `J_k` at the input: kinetic energy `½ J_k ω_t²` with `ω_t = i_k ω_o`.
//!   During a shift the input and the output turn independently and the parts' energy is a quadratic
//!   form in `(ω_t, ω_o)` that must equal `½ J_from ω_t²` on the off-going gear's line and
//!   `½ J_to ω_t²` on the on-coming gear's, or the gear change creates or destroys energy. The form
//!   used is the one of a single lumped member turning at `α ω_t + β ω_o` ([`shift_inertia_form`]):
//!   positive semi-definite and exact on both lines. The change of reflected inertia between gears
//!   is then no loss; the only energy a shift dissipates is the clutches' slip.
//! * **Shift control of an upshift** (a modern automatic's clutch-to-clutch upshift):
//!   - torque phase (`shift_handover_s`): the off-going clutch's capacity ramps from
//!     `shift_clutch_capacity_nm` to 0, the on-coming clutch's from 0 to the input torque;
//!   - inertia phase (handover to synchronisation): the on-coming clutch's capacity rises over
//!     [`CAPACITY_RAMP_S`] to the input torque at the shift's start plus the inertia torque that
//!     closes the slip in `upshift_inertia_phase_s` (open-loop feed-forward; no more than gives the
//!     off-going gear's output torque, `i_from η_from / i_to` times that input torque, so the output
//!     torque does not rise above its level before the shift; at least the present input torque plus
//!     [`SYNC_MARGIN`] of the inertia torque, and at least the present input torque plus the torque
//!     that closes the remaining slip by the deadline [`LONGEST_INERTIA_PHASE`] ×
//!     `upshift_inertia_phase_s` after the handover, capped at `shift_clutch_capacity_nm`), and the
//!     engine's torque is reduced by `upshift_torque_reduction` (spark retard, fuel cut), ramped in
//!     over [`TORQUE_REDUCTION_RAMP_S`] and restored over the last [`TORQUE_RESTORE_SLIP`] of the
//!     slip.
//!
//!   This is for power-on upshifts: the TCU's power-on/power-off decision at the shift command
//!   ([`ShiftControl::is_power_on`]) calls an upshift power-on when the input torque is above
//!   `upshift_power_on_nm` (default 0). Below it the engine hardly pulls: the output-torque cap
//!   would hold the on-coming clutch near that small torque and the inertia phase would crawl, so
//!   the upshift is a power-off one (constant capacity, no torque reduction). Without
//!   `upshift_inertia_phase_s` the on-coming capacity ramps to `shift_clutch_capacity_nm` and stays
//!   there (the behaviour before shift control). Power-off upshifts and downshifts keep that constant
//!   capacity and no torque reduction.

use super::range::{field, Range};
use crate::error::CoreResult;

/// `[gearbox].upshift_torque_reduction`: fraction of the engine's torque withheld in the inertia
/// phase of an upshift, from 0 to 0.9. Typical 0.3–0.6 (spark retard; up to a full cut by fuel
/// cut-off): 0.9 keeps the engine firing.
pub const TORQUE_REDUCTION: Range = Range { low: Some((0.0, true)), high: Some((0.9, true)) };
/// `[gearbox].upshift_inertia_phase_s`, s: from 0.05 to 2. Typical 0.2–0.5 s for a passenger
/// car's upshift; shorter is a harsh shift, longer heats the clutch.
pub const INERTIA_PHASE: Range = Range { low: Some((0.05, true)), high: Some((2.0, true)) };
/// Time over which the engine's torque reduction is applied after the handover, s (the torque
/// intervention's rate: a few firing intervals).
pub const TORQUE_REDUCTION_RAMP_S: f64 = 0.05;
/// The reduction fades out linearly over this last fraction of the on-coming clutch's slip, so the
/// engine's torque is back when the clutch locks.
pub const TORQUE_RESTORE_SLIP: f64 = 0.2;
/// `[gearbox].upshift_power_on_nm`, N·m at the gearbox input: at least 0 (finite). An upshift is
/// power-on when the input torque at its command is above it. Typical: a few per cent of the
/// engine's peak torque (assumed); 0 is the rule before the threshold (any positive torque).
pub const POWER_ON_THRESHOLD: Range = Range::NON_NEGATIVE;
/// In the inertia phase the on-coming clutch's capacity exceeds the present input torque by at
/// least this fraction of the target inertia torque, so the slip closes however the input torque
/// rises.
pub const SYNC_MARGIN: f64 = 0.1;
/// The longest inertia phase of a power-on upshift, in multiples of `upshift_inertia_phase_s` (the
/// TCU's supervision of the synchronisation time): the on-coming clutch's capacity exceeds the
/// present input torque by at least `J × remaining slip / time left to this deadline` (the time
/// left no less than [`CAPACITY_RAMP_S`]), so a shift that starts with a small input torque, where
/// the output-torque cap holds the clutch near that torque, still synchronises in time (the cap
/// then gives way). A shift on time needs less and is unchanged.
pub const LONGEST_INERTIA_PHASE: f64 = 2.5;
/// Time over which the on-coming clutch's capacity rises from the input torque to its inertia-phase
/// value after the handover, s.
pub const CAPACITY_RAMP_S: f64 = 0.05;

/// The shift control of an upshift: engine torque reduction and the on-coming clutch's target
/// inertia phase. The default is none (constant clutch capacity, no torque reduction).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ShiftControl {
    /// Fraction of the engine's torque withheld in the inertia phase, 0–0.9.
    pub torque_reduction: f64,
    /// Target duration of the inertia phase, s; None: constant on-coming capacity.
    pub inertia_phase_s: Option<f64>,
    /// Input torque above which an upshift is power-on, N·m, ≥ 0.
    pub power_on_nm: f64,
}

impl ShiftControl {
    /// The fields' ranges, errors named as the vehicle file names them.
    pub fn validate(&self) -> CoreResult<()> {
        TORQUE_REDUCTION.check(&field("gearbox", "upshift_torque_reduction"), self.torque_reduction)?;
        if let Some(t) = self.inertia_phase_s {
            INERTIA_PHASE.check(&field("gearbox", "upshift_inertia_phase_s"), t)?;
        }
        POWER_ON_THRESHOLD.check(&field("gearbox", "upshift_power_on_nm"), self.power_on_nm)?;
        Ok(())
    }

    /// The TCU's power-on/power-off decision at an upshift's command: power-on (controlled
    /// on-coming capacity and torque reduction) when the input torque `start_input_nm`, N·m, is
    /// above `upshift_power_on_nm`; otherwise power-off (constant capacity, no torque reduction).
    pub fn is_power_on(&self, start_input_nm: f64) -> bool {
        start_input_nm > self.power_on_nm
    }

    /// The on-coming clutch's capacity in an upshift, N·m at the input, or None without a target
    /// inertia phase. `input_nm`: the torque into the gearbox now; `phase`: the inertia phase's
    /// data (None in the torque phase); `torque_phase_done`: the fraction of the torque phase done;
    /// `capacity_nm`: the clutch's maximum.
    ///
    /// Torque phase: the input torque times `torque_phase_done`. Inertia phase: the input torque at
    /// the shift's start plus the inertia torque `J Δω / upshift_inertia_phase_s` (rising over
    /// [`CAPACITY_RAMP_S`]), but no more than the output torque before the shift allows
    /// (`step` × that input torque); at least the present input torque plus [`SYNC_MARGIN`] of the
    /// inertia torque, so the slip always closes, and plus the torque that closes the remaining slip
    /// by [`LONGEST_INERTIA_PHASE`] target phases after the handover, so it closes in time.
    pub fn oncoming_capacity_nm(
        &self,
        input_nm: f64,
        phase: Option<&InertiaPhase>,
        torque_phase_done: f64,
        capacity_nm: f64,
    ) -> Option<f64> {
        let tau = self.inertia_phase_s?;
        let now = input_nm.max(0.0);
        let c = match phase {
            None => torque_phase_done * now,
            Some(p) => {
                let held = p.start_nm.max(0.0);
                let inertia = p.inertia_kg_m2 * p.slip_rad_s.max(0.0) / tau;
                let rise = (p.since_s / CAPACITY_RAMP_S).clamp(0.0, 1.0);
                let left_s = (LONGEST_INERTIA_PHASE * tau - p.since_s).max(CAPACITY_RAMP_S);
                let deadline = p.inertia_kg_m2 * p.remaining_rad_s.max(0.0) / left_s;
                (held + rise * inertia)
                    .min(held.max(p.step * held))
                    .max(now + SYNC_MARGIN * rise * inertia)
                    .max(now + rise * deadline)
            }
        };
        Some(c.min(capacity_nm))
    }

    /// The fraction of the engine's torque delivered in the inertia phase of an upshift:
    /// `1 − r·ramp·fade`, ramp over [`TORQUE_REDUCTION_RAMP_S`] after the handover, fade over the
    /// last [`TORQUE_RESTORE_SLIP`] of the slip (`remaining`: the on-coming slip over the slip of the
    /// whole shift).
    pub fn engine_factor(&self, since_handover_s: f64, remaining: f64) -> f64 {
        let ramp = (since_handover_s / TORQUE_REDUCTION_RAMP_S).clamp(0.0, 1.0);
        let fade = (remaining / TORQUE_RESTORE_SLIP).clamp(0.0, 1.0);
        1.0 - self.torque_reduction * ramp * fade
    }
}

/// What the on-coming clutch's feed-forward knows in an upshift's inertia phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaPhase {
    /// The torque into the gearbox when the shift started, N·m.
    pub start_nm: f64,
    /// `i_from η_from / i_to`: the on-coming clutch's torque that gives the output torque of the
    /// off-going gear, per unit input torque.
    pub step: f64,
    /// The input side's inertia, kg·m².
    pub inertia_kg_m2: f64,
    /// The slip a whole shift closes at the present output speed, `(i_from − i_to) ω_o`, rad/s.
    pub slip_rad_s: f64,
    /// The on-coming clutch's slip now, `ω_t − i_to ω_o`, rad/s.
    pub remaining_rad_s: f64,
    /// Time since the handover, s.
    pub since_s: f64,
}

/// The gearbox's inertia during a shift from gear ratio `i_from` (input inertia `j_from`, kg·m²)
/// to `i_to` (`j_to`): `[a, b, c]` of the kinetic energy `½ (a ω_t² + 2 b ω_t ω_o + c ω_o²)`, the
/// energy of one member turning at `α ω_t + β ω_o` with `α = (√E_f − √E_t)/(i_f − i_t)`,
/// `β = (√E_t i_f − √E_f i_t)/(i_f − i_t)`, `E_k = J_k i_k²`. On either gear's line
/// (`ω_t = i_k ω_o`) it is `½ J_k ω_t²`; with `J_from = J_to` it is `J` on the input alone.
pub fn shift_inertia_form(j_from: f64, i_from: f64, j_to: f64, i_to: f64) -> [f64; 3] {
    let (ef, et) = ((j_from * i_from * i_from).sqrt(), (j_to * i_to * i_to).sqrt());
    let d = i_from - i_to;
    let alpha = (ef - et) / d;
    let beta = (et * i_from - ef * i_to) / d;
    [alpha * alpha, alpha * beta, beta * beta]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inertia_form_is_each_gears_inertia_on_its_line_and_never_negative() {
        for (jf, i_f, jt, it) in [(0.06, 5.25, 0.05, 3.029), (0.035, 0.809, 0.034, 0.673), (0.04, 1.0, 0.06, 2.0)] {
            let [a, b, c] = shift_inertia_form(jf, i_f, jt, it);
            let energy = |wt: f64, wo: f64| 0.5 * (a * wt * wt + 2.0 * b * wt * wo + c * wo * wo);
            let wo = 100.0;
            assert!((energy(i_f * wo, wo) - 0.5 * jf * (i_f * wo).powi(2)).abs() < 1e-9);
            assert!((energy(it * wo, wo) - 0.5 * jt * (it * wo).powi(2)).abs() < 1e-9);
            assert!(a >= 0.0 && c >= 0.0 && a * c - b * b >= -1e-12);
        }
        let [a, b, c] = shift_inertia_form(0.05, 4.0, 0.05, 2.0);
        assert!((a - 0.05).abs() < 1e-15 && b.abs() < 1e-15 && c.abs() < 1e-15);
    }

    #[test]
    fn oncoming_capacity_carries_the_input_then_adds_the_inertia_torque() {
        let s = ShiftControl { torque_reduction: 0.5, inertia_phase_s: Some(0.4), power_on_nm: 0.0 };
        // half-way through the torque phase: half the input torque
        assert_eq!(s.oncoming_capacity_nm(200.0, None, 0.5, 500.0), Some(100.0));
        // in the inertia phase: the handover's input plus 0.1 kg m² · 200 rad/s / 0.4 s = 50 N·m,
        // capped; at least the present input plus a tenth of the inertia torque
        let p = InertiaPhase {
            start_nm: 200.0,
            step: 1.5,
            inertia_kg_m2: 0.1,
            slip_rad_s: 200.0,
            remaining_rad_s: 1.0,
            since_s: 0.5,
        };
        assert_eq!(s.oncoming_capacity_nm(150.0, Some(&p), 1.0, 500.0), Some(250.0));
        assert_eq!(s.oncoming_capacity_nm(300.0, Some(&p), 1.0, 500.0), Some(305.0));
        assert_eq!(s.oncoming_capacity_nm(200.0, Some(&p), 1.0, 220.0), Some(220.0));
        assert_eq!(s.oncoming_capacity_nm(200.0, Some(&InertiaPhase { since_s: 0.0, ..p }), 1.0, 500.0), Some(200.0));
        // no more output torque than before the shift: 1.1 × 200 N·m
        let capped = s.oncoming_capacity_nm(150.0, Some(&InertiaPhase { step: 1.1, ..p }), 1.0, 500.0).unwrap();
        assert!((capped - 220.0).abs() < 1e-9, "{capped}");
        assert_eq!(ShiftControl::default().oncoming_capacity_nm(200.0, Some(&p), 1.0, 500.0), None);
        // reduction: none at the handover, full after the ramp, gone at the synchronisation
        assert_eq!(s.engine_factor(0.0, 1.0), 1.0);
        assert_eq!(s.engine_factor(1.0, 1.0), 0.5);
        assert_eq!(s.engine_factor(1.0, 0.0), 1.0);
    }

    #[test]
    fn an_upshift_is_power_on_only_above_the_threshold() {
        let s = ShiftControl { torque_reduction: 0.5, inertia_phase_s: Some(0.4), power_on_nm: 20.0 };
        assert!(!s.is_power_on(3.0) && !s.is_power_on(20.0) && !s.is_power_on(-5.0));
        assert!(s.is_power_on(20.5) && s.is_power_on(300.0));
        // the default threshold 0: any positive input torque
        let d = ShiftControl { power_on_nm: 0.0, ..s };
        assert!(d.is_power_on(3.0) && !d.is_power_on(0.0));
    }

    #[test]
    fn a_tiny_input_torque_still_closes_the_slip_by_the_deadline() {
        // 3 N·m at the command (a tip-out), 1→2 step 1.7, 0.1 kg m², 76 rad/s to close: the
        // output-torque cap alone allows 5.1 N·m, 2.1 N·m above the input (3.6 s for 76 rad/s)
        let s = ShiftControl { torque_reduction: 0.5, inertia_phase_s: Some(0.4), power_on_nm: 0.0 };
        let deadline_s = LONGEST_INERTIA_PHASE * 0.4;
        for (since_s, remaining_rad_s) in [(0.2, 76.0), (0.6, 40.0), (0.95, 5.0), (1.5, 2.0)] {
            let p = InertiaPhase {
                start_nm: 3.0,
                step: 1.7,
                inertia_kg_m2: 0.1,
                slip_rad_s: 76.0,
                remaining_rad_s,
                since_s,
            };
            for now in [3.0, 0.5, -10.0, 40.0] {
                let c = s.oncoming_capacity_nm(now, Some(&p), 1.0, 500.0).unwrap();
                let closing_s = p.inertia_kg_m2 * remaining_rad_s / (c - now.max(0.0));
                assert!(since_s + closing_s <= deadline_s.max(since_s + CAPACITY_RAMP_S) + 1e-9, "{since_s} {now} {c}");
            }
        }
        // a shift on time is left alone: 2 N·m of deadline torque is below the cap's 100 N·m
        let p = InertiaPhase {
            start_nm: 200.0,
            step: 1.5,
            inertia_kg_m2: 0.1,
            slip_rad_s: 200.0,
            remaining_rad_s: 10.0,
            since_s: 0.5,
        };
        assert_eq!(s.oncoming_capacity_nm(200.0, Some(&p), 1.0, 500.0), Some(250.0));
    }

    #[test]
    fn validation_names_the_field() {
        let bad = ShiftControl { torque_reduction: 0.95, inertia_phase_s: None, power_on_nm: 0.0 };
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].upshift_torque_reduction");
        let bad = ShiftControl { torque_reduction: 0.4, inertia_phase_s: Some(0.01), power_on_nm: 0.0 };
        assert_eq!(bad.validate().unwrap_err().field, "[gearbox].upshift_inertia_phase_s");
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let bad = ShiftControl { torque_reduction: 0.4, inertia_phase_s: Some(0.3), power_on_nm: bad };
            assert_eq!(bad.validate().unwrap_err().field, "[gearbox].upshift_power_on_nm");
        }
        ShiftControl { torque_reduction: 0.4, inertia_phase_s: Some(0.3), power_on_nm: 20.0 }.validate().unwrap();
    }
}
