mod common;

use common::*;
use tcsim_core::transient::{simulate, InitialState, SolverOptions};

#[test]
fn smoke() {
    let m = ht(SHAPE);
    let t = grid(0.0, 10.0, 1001);
    let start = std::time::Instant::now();
    let r = simulate(&m, &takeoff(false), &t, &InitialState::default(), &SolverOptions::default()).unwrap();
    println!("{:?} steps {} events {:?}", start.elapsed(), r.steps, r.events);
    println!("{:?}", r.samples.last().unwrap());
    let o = SolverOptions { max_events: 20, ..Default::default() };
    let r = tcsim_core::transient::simulate(&m, &takeoff(true), &t, &InitialState::default(), &o);
    if let Err(e) = &r { println!("{e}"); }
    let r = r.unwrap();
    println!("steps {} events {:?}", r.steps, r.events);
    println!("{:?}", r.samples.last().unwrap());
}
