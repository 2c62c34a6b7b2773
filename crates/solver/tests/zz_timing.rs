mod common;
use odocal_geom::Pose2;
use odocal_solver::*;
fn cpu_ns() -> u64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap();
    s.split_whitespace().next().unwrap().parse().unwrap()
}
#[test]
fn timing() {
    let truth = Params { r_l: 0.0305, r_r: 0.0298, b: 0.32, laser: Pose2::new(0.08, -0.03, 0.6) };
    for n in [1000usize, 10_000, 100_000] {
        let mut r = common::rng(7);
        let mut s = common::exact_samples(&mut r, &truth, n, 1);
        common::add_noise(&mut r, &mut s, [0.002, 0.002, 0.004]);
        for x in s.iter_mut().step_by(100) { x.sm = Pose2::new(x.sm.x + 0.2, x.sm.y - 0.1, x.sm.theta + 0.3); }
        for refine in [true, false] {
            let o = SolveOptions { refine, ..SolveOptions::default() };
            let reps = (200_000 / n).max(3);
            let _ = calibrate(&s, &o).unwrap();
            let t0 = cpu_ns(); let w0 = std::time::Instant::now();
            let mut it = 0;
            for _ in 0..reps { let c = calibrate(&s, &o).unwrap(); it += c.refinement.map_or(0, |r| r.iterations); }
            let cpu = (cpu_ns() - t0) as f64 / reps as f64 / 1e6;
            let wall = w0.elapsed().as_secs_f64() / reps as f64 * 1e3;
            println!("n {n} refine {refine}: cpu {cpu:.3} ms wall {wall:.3} ms LM iters {}", it / reps);
        }
    }
}
