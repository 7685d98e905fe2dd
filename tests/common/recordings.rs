//! Real recordings of struck objects shipped by Debian packages, decoded for the fitting tests:
//! FLAC files (Sonic Pi's samples) and Gravis UltraSound patches (freepats).

use std::path::Path;

use modal_resonator::authoring::fit::Recording;

use super::decode::{read_flac, read_gus_patch};

/// A recording the tests fit, with where it comes from.
pub struct RealRecording {
    /// Short name, also the file name of the derived preset.
    pub slug: &'static str,
    /// What the object is.
    pub object: &'static str,
    /// Debian package that installs the file.
    pub package: &'static str,
    /// Where the package installs it.
    pub path: &'static str,
    /// Which sample of a multi-sample patch (0 for other files).
    pub sample: usize,
    /// SPDX licence of the recording, from the package's copyright file.
    pub license: &'static str,
    /// Who made the recording and where it was published, from the same file.
    pub credit: &'static str,
    /// What the object is and how it sounds, for the bank's description.
    pub about: &'static str,
    /// About where the note the object is played as lies, in Hz: the bank's root is the fitted
    /// mode nearest it.
    pub root_near_hz: f64,
    /// Highest log-spectral distance in dB the fitted bank may have from the recording: about
    /// 1.5 dB above what the fit reached when the bound was set, so a change that makes the fit
    /// worse fails.
    pub max_lsd_db: f64,
}

/// The recordings: bells, tubular bells, glockenspiel, marimba, celesta, cowbell.
pub const REAL_RECORDINGS: &[RealRecording] = &[
    RealRecording {
        slug: "tubular-bell",
        object: "Tubular bell",
        package: "freepats",
        path: "/usr/share/midi/freepats/Tone_000/014_Tubular_Bells.pat",
        sample: 0,
        license: "GPL-2.0-or-later",
        credit: "freepats (freepats.zenvoid.org), 014_Tubular_Bells.pat",
        max_lsd_db: 7.0,
        about: "A tubular bell (orchestral chime) struck on its cap: a bright attack over low \
                partials that ring for tens of seconds. The strike note is heard an octave \
                below the root, implied by the root and the two partials above it (close to \
                2 : 3 : 4).",
        root_near_hz: 1402.0,
    },
    RealRecording {
        slug: "glockenspiel",
        object: "Glockenspiel bar",
        package: "freepats",
        path: "/usr/share/midi/freepats/Tone_000/009_Glockenspiel.pat",
        sample: 2,
        license: "GPL-2.0-or-later",
        credit: "freepats (freepats.zenvoid.org), 009_Glockenspiel.pat, sample 3",
        max_lsd_db: 6.5,
        about: "A glockenspiel bar at A6 struck with a mallet: a piercing, bell-like ping \
                whose fundamental rings for seconds while the bright upper partials die within \
                a second.",
        root_near_hz: 1760.0,
    },
    RealRecording {
        slug: "marimba",
        object: "Marimba bar",
        package: "freepats",
        path: "/usr/share/midi/freepats/Tone_000/013_Xylophone.pat",
        sample: 3,
        license: "GPL-2.0-or-later",
        credit: "freepats (freepats.zenvoid.org), 013_Xylophone.pat, sample 4 (C4 marimba)",
        max_lsd_db: 9.0,
        about: "A marimba bar near middle C struck with a mallet: a warm, round, woody note \
                with a short ring.",
        root_near_hz: 263.0,
    },
    RealRecording {
        slug: "celesta",
        object: "Celesta",
        package: "freepats",
        path: "/usr/share/midi/freepats/Tone_000/008_Celesta.pat",
        sample: 0,
        license: "GPL-2.0-or-later",
        credit: "freepats (freepats.zenvoid.org), 008_Celesta.pat, sample 1",
        max_lsd_db: 9.0,
        about: "A celesta note (C#5): a steel plate struck by a felt hammer, a soft, sweet, \
                music-box-like tone.",
        root_near_hz: 554.0,
    },
    RealRecording {
        slug: "hand-bell",
        object: "Bell",
        package: "sonic-pi-samples",
        path: "/usr/share/sonic-pi/samples/perc_bell.flac",
        sample: 0,
        license: "CC0-1.0",
        credit: "AlaskaRobotics, freesound.org/people/AlaskaRobotics/sounds/221515 (Sonic Pi's \
                 perc_bell)",
        max_lsd_db: 9.5,
        about: "A small bell with a high, shimmering ring: a strong partial at the root that \
                lasts for seconds under a brighter, quicker one.",
        root_near_hz: 3621.0,
    },
    RealRecording {
        slug: "cowbell",
        object: "Cowbell",
        package: "sonic-pi-samples",
        path: "/usr/share/sonic-pi/samples/drum_cowbell.flac",
        sample: 0,
        license: "CC0-1.0",
        credit: "Neotone, freesound.org/people/Neotone/sounds/75338 (Sonic Pi's drum_cowbell)",
        max_lsd_db: 11.0,
        about: "A cowbell struck with a stick: a short, clanky, hollow knock, its pitch set by \
                the two partials near 645 Hz and 1.6 kHz; the root is the lower, longer one.",
        root_near_hz: 645.0,
    },
];

impl RealRecording {
    /// Decodes the recording as mono, or panics saying which package to install.
    pub fn load(&self, position: &str) -> Recording {
        let path = Path::new(self.path);
        assert!(
            path.exists(),
            "{} is missing: install the Debian package {} (apt-get install {})",
            self.path,
            self.package,
            self.package
        );
        if self.path.ends_with(".flac") {
            read_flac(path, position)
        } else {
            read_gus_patch(path, self.sample, position)
        }
    }
}
