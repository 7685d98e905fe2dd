use modal_resonator::model::materials::STEEL;
use modal_resonator::model::mesh::{generate, solve_modes, MeshSettings};

#[test]
fn scratch_bar() {
    for elements in [2000usize, 6000, 20000] {
        let bar = generate::cuboid([0.3, 0.03, 0.01]);
        let settings = MeshSettings { material: STEEL, elements, clamps: vec![], modes: 20 };
        let t = std::time::Instant::now();
        let modes = solve_modes(&bar, &settings, &mut |_| {}).unwrap();
        println!("elements {} voxel {:.3} mm dofs {} steps {} rigid {} factor {} time {:?} stats {:?}", modes.stats.elements, modes.stats.voxel_m*1e3, modes.stats.dofs, modes.stats.steps, modes.stats.rigid_modes, modes.stats.factor_entries, t.elapsed(), modes.stats);
        println!("{:?}", modes.freqs_hz.iter().map(|f| (f*10.0).round()/10.0).collect::<Vec<_>>());
    }
}
