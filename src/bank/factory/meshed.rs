//! Factory banks made from meshes: the files in `presets/meshed/`, made by `modal-resonator mesh`
//! from the surfaces in `presets/meshes/`, which code in the project generates
//! ([`crate::authoring::mesh::generate::FACTORY_MESHES`]). Built into the program, as the fitted
//! banks are.
//!
//! `tests/mesh_presets.rs` checks that each mesh file is the generator's surface and that the
//! command below, run again, makes the bank in the file; `UPDATE_PRESETS=1 cargo test --release
//! --test mesh_presets` rewrites both.

use crate::bank::{parse_bank_str, Bank};

/// A meshed factory bank: its file, the mesh it was made from and the command that made it.
pub struct MeshedPreset {
    /// File name in `presets/meshed/`.
    pub file: &'static str,
    /// The file's JSON.
    pub json: &'static str,
    /// File name of the mesh in `presets/meshes/`.
    pub mesh_file: &'static str,
    /// The options of `modal-resonator mesh` after the mesh's path (and before `-o`).
    pub options: &'static [&'static str],
}

/// Embeds `presets/meshed/<name>`.
macro_rules! meshed {
    ($file:literal) => {
        include_str!(concat!("../../../presets/meshed/", $file))
    };
}

/// The meshed banks, in display order.
pub const MESHED_PRESETS: [MeshedPreset; 3] = [
    MeshedPreset {
        file: "porcelain-cup-meshed.json",
        json: meshed!("porcelain-cup-meshed.json"),
        mesh_file: "cup.obj",
        options: &[
            "--name",
            "Porcelain cup (meshed)",
            "--material",
            "porcelain",
            "--elements",
            "16000",
            "--modes",
            "60",
            "--positions",
            "rim=0.04,0,0.088; rim 45=0.02828,0.02828,0.088; side=0.04,0,0.045; base=0.02,0,0",
        ],
    },
    MeshedPreset {
        file: "steel-tuning-fork-meshed.json",
        json: meshed!("steel-tuning-fork-meshed.json"),
        mesh_file: "tuning-fork.obj",
        options: &[
            "--name",
            "Steel tuning fork (meshed)",
            "--material",
            "steel",
            "--elements",
            "12000",
            "--modes",
            "40",
            "--positions",
            "prong tip=-0.01,0.003,0.084; prong middle=-0.01,0.003,0.045; \
             prong face=-0.007,0,0.08; stem end=0,0.003,-0.04",
        ],
    },
    MeshedPreset {
        file: "bronze-bell-meshed.json",
        json: meshed!("bronze-bell-meshed.json"),
        mesh_file: "bell.obj",
        options: &[
            "--name",
            "Bronze bell (meshed)",
            "--material",
            "bronze",
            "--elements",
            "16000",
            "--modes",
            "60",
            "--positions",
            "sound bow=0.059,0,0.003; waist=0.034,0,0.06; shoulder=0.031,0,0.09; crown=0,0,0.1",
        ],
    },
];

impl MeshedPreset {
    /// The bank. The files are checked by the tests, so a broken one is a bug in the build.
    pub fn bank(&self) -> Bank {
        parse_bank_str(self.json, &format!("presets/meshed/{}", self.file))
            .unwrap_or_else(|e| panic!("a built-in meshed bank is invalid: {e}"))
    }

    /// The file name without `.json`, which also finds the bank by name.
    pub fn stem(&self) -> &'static str {
        self.file.trim_end_matches(".json")
    }

    /// The command that made the bank, as `presets/README.md` gives it (from the repository's
    /// top folder).
    pub fn command(&self) -> String {
        let quoted: Vec<String> = self
            .options
            .iter()
            .map(|o| {
                if o.contains([' ', ';']) {
                    format!("\"{o}\"")
                } else {
                    o.to_string()
                }
            })
            .collect();
        format!(
            "modal-resonator mesh presets/meshes/{} {} -o presets/meshed/{}",
            self.mesh_file,
            quoted.join(" "),
            self.file
        )
    }
}
