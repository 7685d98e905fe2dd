//! Modes from meshes: for the 300 x 30 x 10 mm steel bar and the generated bronze bell, each
//! at 20,000 elements with 100 modes asked, the elements, degrees of freedom, entries of the
//! stiffness matrix and of its Cholesky factor, Lanczos steps, modes found, the time of each
//! stage and the peak memory of the process that solved it.
//!
//! Run with `cargo bench --bench mesh` (one core: the solver runs on one thread). `MESH_ELEMENTS`
//! and `MESH_MODES` change the size. Each case runs in a child process of its own, so its peak
//! memory (`VmHWM`) is its own. Without `--bench` (as `cargo test --all-targets` runs it) it
//! solves a small bar once.

use std::process::Command;
use std::time::Instant;

use modal_resonator::authoring::materials::{BRONZE, STEEL};
use modal_resonator::authoring::mesh::{generate, solve_modes, MeshSettings};

/// Set in a child process to the case it runs.
const CASE_VAR: &str = "MESH_BENCH_CASE";

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Peak resident memory of this process in MiB, from `/proc/self/status`.
fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Solves one case and prints its row.
fn run_case(case: &str, elements: usize, modes: usize) {
    let (surface, material) = match case {
        "bar" => (generate::cuboid([0.3, 0.03, 0.01]), STEEL),
        "bell" => (generate::bell(), BRONZE),
        other => panic!("unknown case {other}"),
    };
    let settings = MeshSettings {
        material,
        elements,
        clamps: vec![],
        modes,
    };
    let started = Instant::now();
    let solved = solve_modes(&surface, &settings, &mut |_| {}).expect("the case solves");
    let total = started.elapsed().as_secs_f64();
    let s = &solved.stats;
    println!(
        "{case:<5} {:>8} {:>8} {:>10} {:>11} {:>6} {:>6} {:>9.3} {:>9.3} {:>9.2} {:>10.2} {:>8.2} {:>9.0}",
        s.elements,
        s.dofs,
        s.matrix_entries,
        s.factor_entries,
        s.steps,
        solved.freqs_hz.len(),
        s.voxelising.as_secs_f64(),
        s.assembling.as_secs_f64(),
        s.factorising.as_secs_f64(),
        s.iterating.as_secs_f64(),
        total,
        peak_mib()
    );
    println!(
        "      lowest {:.1} Hz, highest {:.1} Hz, {} rigid motions left out",
        solved.freqs_hz[0],
        solved.freqs_hz[solved.freqs_hz.len() - 1],
        s.rigid_modes
    );
}

fn main() {
    if let Ok(case) = std::env::var(CASE_VAR) {
        run_case(
            &case,
            env_usize("MESH_ELEMENTS", 20_000),
            env_usize("MESH_MODES", 100),
        );
        return;
    }
    if !std::env::args().any(|a| a == "--bench") {
        run_case("bar", 2_000, 12);
        return;
    }
    println!(
        "case  elements     dofs  K entries  L entries  steps  modes  voxels s  assemb s  factor s  Lanczos s  total s  peak MiB"
    );
    let exe = std::env::current_exe().expect("the bench's own path");
    for case in ["bar", "bell"] {
        let status = Command::new(&exe)
            .env(CASE_VAR, case)
            .status()
            .expect("the case runs");
        assert!(status.success(), "{case} failed");
    }
}
