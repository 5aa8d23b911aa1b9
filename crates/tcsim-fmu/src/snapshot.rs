//! FMU state (`fmi2GetFMUstate`/`fmi2SetFMUstate` and their serialisation): everything the
//! continuation of an instance depends on, so that a restored state continues bit for bit.
//!
//! The serialised form is versioned and checked: `TCSIMFS\0`, the format version (u32), the
//! fingerprint of the FMU's model (u64: the model specification, the causality and the parameter
//! table), the number of words (u32), then the words (f64), all little-endian. A byte string that
//! is truncated, of another version, of another FMU (another model or causality) or of the other
//! interface is refused with a message; nothing panics.

use tcsim_core::engine::converter_events::Mode;
use tcsim_core::engine::lockup::ClutchMode;
use tcsim_core::engine::stepper::{Stepper, StepperState};

use crate::instance::{Instance, ModelExchange, Phase};
use crate::variables::{self, Model, COORDINATES, SIGNAL_SLOTS, START_PARAMETERS};

const MAGIC: &[u8; 8] = b"TCSIMFS\0";
/// Version of the serialised form; a change of the layout increments it.
pub const FORMAT_VERSION: u32 = 1;
const HEADER: usize = 8 + 4 + 8 + 4;
/// Marks a live [`Snapshot`] behind an `fmi2FMUstate` pointer.
const LIVE: u64 = 0x7463_7369_6d46_5355;

/// An FMU state: a copy of the instance's state.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    live: u64,
    fingerprint: u64,
    model_exchange: bool,
    phase: Phase,
    start_time: f64,
    rtol: f64,
    fresh: bool,
    rebuild: bool,
    signals: [f64; SIGNAL_SLOTS],
    rates: [Option<f64>; SIGNAL_SLOTS],
    start: [f64; START_PARAMETERS.len()],
    previous: Option<(f64, [f64; 2])>,
    derivatives: [f64; COORDINATES as usize],
    /// Co-Simulation: the stepper's state.
    stepper: Option<StepperState>,
    /// Model Exchange: time, coordinates, modes.
    me: Option<(f64, [f64; 4], Mode)>,
    parameters: Vec<f64>,
}

/// FNV-1a, 64 bit.
fn fnv(bytes: &[u8], mut h: u64) -> u64 {
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}

impl Instance {
    /// What identifies the FMU a state belongs to: the model specification, the causality and
    /// the parameter table (not the parameter values, which are part of the state).
    pub fn fingerprint(&self) -> u64 {
        let mut h =
            fnv(serde_json::to_string(&self.config.model).unwrap_or_default().as_bytes(), 0xcbf2_9ce4_8422_2325);
        h = fnv(format!("{:?}", self.config.causality).as_bytes(), h);
        for p in &self.config.parameters {
            h = fnv(format!("{}[{}]", p.key, p.index).as_bytes(), h);
        }
        h
    }

    /// `fmi2GetFMUstate`.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            live: LIVE,
            fingerprint: self.fingerprint(),
            model_exchange: self.model_exchange,
            phase: self.phase,
            start_time: self.start_time,
            rtol: self.options.rtol,
            fresh: self.fresh,
            rebuild: self.rebuild,
            signals: self.signals,
            rates: self.rates,
            start: self.start,
            previous: self.previous,
            derivatives: self.derivatives,
            stepper: self.stepper.as_ref().map(Stepper::state),
            me: self.me.as_ref().map(|me| (me.time_s, me.u, me.mode)),
            parameters: self.config.parameters.iter().map(|p| p.value).collect(),
        }
    }

    /// `fmi2SetFMUstate`: continue from `s` (of this FMU and interface). A refused state changes
    /// nothing.
    pub fn restore(&mut self, s: &Snapshot) -> Result<(), String> {
        s.check_live()?;
        if s.fingerprint != self.fingerprint() {
            return Err("FMU state of another FMU (another model, causality or parameter table)".into());
        }
        if s.model_exchange != self.model_exchange {
            return Err("FMU state of the other interface (Model Exchange / Co-Simulation)".into());
        }
        let mut parameters = self.config.parameters.clone();
        for (p, v) in parameters.iter_mut().zip(&s.parameters) {
            p.value = *v;
        }
        let saved = std::mem::replace(&mut self.config.parameters, parameters);
        let mut options = self.options;
        options.rtol = s.rtol;
        let built = if s.stepper.is_some() || s.me.is_some() { Some(self.model()) } else { None };
        let model = match built.transpose() {
            Ok(m) => m,
            Err(e) => {
                self.config.parameters = saved;
                return Err(e.to_string());
            }
        };
        self.stepper = None;
        self.me = None;
        match (model, s.stepper.as_ref(), s.me) {
            (Some(model), Some(state), _) => {
                let mut stepper = Stepper::new(model, self.config.causality, options);
                stepper.set_state(state);
                self.stepper = Some(stepper);
            }
            (Some(model), None, Some((time_s, u, mode))) => {
                let kind = self.config.model.get("kind").and_then(|k| k.as_str()).and_then(Model::from_kind);
                let coordinates = kind.map_or_else(Vec::new, |k| {
                    variables::states(k, self.config.causality, self.lag()).into_iter().map(|(_, c)| c).collect()
                });
                self.me = Some(ModelExchange { model, u, mode, time_s, coordinates });
            }
            _ => {}
        }
        self.options = options;
        self.phase = s.phase;
        self.start_time = s.start_time;
        self.fresh = s.fresh;
        self.rebuild = s.rebuild;
        self.signals = s.signals;
        self.rates = s.rates;
        self.start = s.start;
        self.previous = s.previous;
        self.derivatives = s.derivatives;
        Ok(())
    }
}

impl Snapshot {
    /// The instance's phase when the state was taken (for FMI 3.0's finer state machine).
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// An error unless this is a live snapshot (not freed, not a foreign pointer's memory).
    pub fn check_live(&self) -> Result<(), String> {
        if self.live == LIVE {
            Ok(())
        } else {
            Err("not an FMU state of this FMU (freed or foreign)".into())
        }
    }

    /// Mark freed (before the memory is released).
    pub fn kill(&mut self) {
        self.live = 0;
    }

    /// The words of the serialised form, in a fixed layout for the parameter count.
    fn words(&self) -> Vec<f64> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let mut w =
            vec![flag(self.model_exchange), Phase::ALL.iter().position(|p| *p == self.phase).unwrap_or(0) as f64];
        w.extend([self.start_time, self.rtol, flag(self.fresh), flag(self.rebuild)]);
        w.extend(self.signals);
        for r in self.rates {
            w.extend([flag(r.is_some()), r.unwrap_or(0.0)]);
        }
        w.extend(self.start);
        let (tp, prev) = self.previous.unwrap_or((0.0, [0.0; 2]));
        w.extend([flag(self.previous.is_some()), tp, prev[0], prev[1]]);
        w.extend(self.derivatives);
        let st =
            self.stepper.unwrap_or(StepperState { time_s: 0.0, inputs: [0.0; 2], u: [0.0; 4], mode: Mode::default() });
        w.extend([flag(self.stepper.is_some()), st.time_s, st.inputs[0], st.inputs[1]]);
        w.extend(st.u);
        push_mode(&mut w, &st.mode);
        let (t, u, mode) = self.me.unwrap_or((0.0, [0.0; 4], Mode::default()));
        w.extend([flag(self.me.is_some()), t]);
        w.extend(u);
        push_mode(&mut w, &mode);
        w.extend(&self.parameters);
        w
    }

    /// `fmi2SerializeFMUstate`: the bytes of the state.
    pub fn to_bytes(&self) -> Vec<u8> {
        let words = self.words();
        let mut out = Vec::with_capacity(HEADER + 8 * words.len());
        out.extend(MAGIC);
        out.extend(FORMAT_VERSION.to_le_bytes());
        out.extend(self.fingerprint.to_le_bytes());
        out.extend((words.len() as u32).to_le_bytes());
        for w in words {
            out.extend(w.to_le_bytes());
        }
        out
    }

    /// `fmi2DeSerializeFMUstate`: the state of `bytes`, checked against `instance` (its FMU, its
    /// interface, the layout's length).
    pub fn from_bytes(bytes: &[u8], instance: &Instance) -> Result<Self, String> {
        let refuse = |why: String| Err(format!("FMU state of {} bytes refused: {why}", bytes.len()));
        if bytes.len() < HEADER || &bytes[..8] != MAGIC {
            return refuse("not a serialised tcsim FMU state".into());
        }
        let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap_or_default());
        let version = u32_at(8);
        if version != FORMAT_VERSION {
            return refuse(format!("format version {version}: expected {FORMAT_VERSION}"));
        }
        let fingerprint = u64::from_le_bytes(bytes[12..20].try_into().unwrap_or_default());
        if fingerprint != instance.fingerprint() {
            return refuse("of another FMU (another model, causality or parameter table)".into());
        }
        let n = u32_at(20) as usize;
        let expected = instance.snapshot().words().len();
        if n != expected || bytes.len() != HEADER + 8 * n {
            return refuse(format!("{n} words in {} bytes: expected {expected} words", bytes.len() - HEADER));
        }
        let words: Vec<f64> =
            bytes[HEADER..].chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default())).collect();
        let s = Reader { words: &words, at: 0 }.snapshot(fingerprint, instance.config.parameters.len());
        match s {
            Ok(s) if s.model_exchange == instance.model_exchange => Ok(s),
            Ok(_) => refuse("of the other interface (Model Exchange / Co-Simulation)".into()),
            Err(why) => refuse(why),
        }
    }
}

fn push_mode(w: &mut Vec<f64>, mode: &Mode) {
    let (tag, since) = match mode.lockup {
        ClutchMode::Armed => (0.0, 0.0),
        ClutchMode::Unarmed { since_s } => (1.0, since_s),
        ClutchMode::Locked => (2.0, 0.0),
    };
    w.extend([if mode.stator_locked { 1.0 } else { 0.0 }, mode.flow_sign, tag, since]);
}

/// Reads the words of [`Snapshot::words`] back, checking every flag and tag.
struct Reader<'a> {
    words: &'a [f64],
    at: usize,
}

impl Reader<'_> {
    fn next(&mut self) -> Result<f64, String> {
        let w = *self.words.get(self.at).ok_or("truncated")?;
        self.at += 1;
        Ok(w)
    }

    fn array<const N: usize>(&mut self) -> Result<[f64; N], String> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.next()?;
        }
        Ok(out)
    }

    fn flag(&mut self) -> Result<bool, String> {
        let w = self.next()?;
        if w == 0.0 || w == 1.0 {
            Ok(w == 1.0)
        } else {
            Err(format!("word {}: {w} where a flag (0 or 1) belongs", self.at - 1))
        }
    }

    fn mode(&mut self) -> Result<Mode, String> {
        let stator_locked = self.flag()?;
        let flow_sign = self.next()?;
        let (tag, since_s) = (self.next()?, self.next()?);
        let lockup = if tag == 0.0 {
            ClutchMode::Armed
        } else if tag == 1.0 {
            ClutchMode::Unarmed { since_s }
        } else if tag == 2.0 {
            ClutchMode::Locked
        } else {
            return Err(format!("lock-up clutch mode {tag}: expected 0, 1 or 2"));
        };
        Ok(Mode { stator_locked, flow_sign, lockup })
    }

    fn snapshot(mut self, fingerprint: u64, parameters: usize) -> Result<Snapshot, String> {
        let model_exchange = self.flag()?;
        let phase = self.next()?;
        let phase = *Phase::ALL
            .get(phase as usize)
            .filter(|_| phase.fract() == 0.0 && phase >= 0.0)
            .ok_or(format!("phase {phase}: expected 0 to 3"))?;
        let (start_time, rtol, fresh, rebuild) = (self.next()?, self.next()?, self.flag()?, self.flag()?);
        let signals = self.array::<SIGNAL_SLOTS>()?;
        let mut rates = [None; SIGNAL_SLOTS];
        for r in &mut rates {
            let (given, value) = (self.flag()?, self.next()?);
            *r = given.then_some(value);
        }
        let start = self.array::<{ START_PARAMETERS.len() }>()?;
        let (has_previous, tp, prev) = (self.flag()?, self.next()?, self.array::<2>()?);
        let derivatives = self.array::<{ COORDINATES as usize }>()?;
        let (has_stepper, time_s, inputs, u) = (self.flag()?, self.next()?, self.array::<2>()?, self.array::<4>()?);
        let mode = self.mode()?;
        let stepper = has_stepper.then_some(StepperState { time_s, inputs, u, mode });
        let (has_me, me_t, me_u, me_mode) = (self.flag()?, self.next()?, self.array::<4>()?, self.mode()?);
        let parameters = (0..parameters).map(|_| self.next()).collect::<Result<Vec<f64>, String>>()?;
        Ok(Snapshot {
            live: LIVE,
            fingerprint,
            model_exchange,
            phase,
            start_time,
            rtol,
            fresh,
            rebuild,
            signals,
            rates,
            start,
            previous: has_previous.then_some((tp, prev)),
            derivatives,
            stepper,
            me: has_me.then_some((me_t, me_u, me_mode)),
            parameters,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instance::Configuration;

    const CONFIG: &str = r#"{"causality": "pump-torque",
        "model": {"kind": "table", "inertia_kg_m2": [0.109, 0.056, 0.01],
                  "speed_ratio": [0.0, 0.5, 1.0], "torque_ratio": [2.1, 1.4, 1.0],
                  "capacity_factor_nm_s2": [0.0032, 0.003, 0.0002]},
        "parameters": [{"key": "torque_ratio", "index": 0}]}"#;

    /// Every prefix and every one-byte change of a serialised state is refused or read back to a
    /// state; none panics, and the intact bytes read back to the same state.
    #[test]
    fn every_truncation_and_byte_change_is_handled() {
        let mut inst = Instance::new(Configuration::parse(CONFIG).unwrap());
        inst.set(0, 100.0).unwrap();
        inst.enter_initialization().unwrap();
        inst.exit_initialization().unwrap();
        inst.do_step(0.0, 0.01).unwrap();
        let bytes = inst.snapshot().to_bytes();
        assert_eq!(Snapshot::from_bytes(&bytes, &inst).unwrap().to_bytes(), bytes); // NaN outputs: compare bits
        for n in 0..bytes.len() {
            assert!(Snapshot::from_bytes(&bytes[..n], &inst).is_err(), "{n} bytes");
        }
        for i in 0..bytes.len() {
            let mut changed = bytes.clone();
            changed[i] ^= 0x5a;
            let _ = Snapshot::from_bytes(&changed, &inst);
        }
        let mut me = Instance::new(Configuration::parse(CONFIG).unwrap());
        me.model_exchange = true;
        assert!(Snapshot::from_bytes(&bytes, &me).unwrap_err().contains("other interface"));
    }
}
