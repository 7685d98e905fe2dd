//! The inner loop: advance rows of resonators over a run of samples.
//!
//! Storage is structure-of-arrays in rows of [`COLUMNS`] modes. Every kernel takes the same slices
//! and adds each mode's output `Im z` into the accumulator lane of its column, one 8-lane sum per
//! sample; the engine later weights the lanes for stereo. Kernels differ only in how many modes
//! they advance at once:
//!
//! - [`Kernel::Scalar`]: one mode at a time, the test oracle;
//! - [`Kernel::Portable`]: two rows of plain arrays the compiler vectorises for any x86-64;
//! - [`Kernel::Avx2`]: AVX2 + FMA, four 8-lane vectors (32 modes) in flight so the 4-cycle FMA
//!   latency is hidden, state in registers for the whole run;
//! - [`Kernel::Avx512`]: AVX-512, four 16-lane vectors (64 modes) in flight.
//!
//! Each takes `rows` as a multiple of its [`Kernel::row_block`] (two rows for the portable kernel,
//! which advances rows in pairs, and for AVX-512, whose vectors span two rows; else one); rows
//! after the last whole group go as a smaller group, so a bank with few modes sounding computes
//! little padding.

mod portable;
mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

/// Modes per row: one accumulator lane (and one stereo position) per column.
pub const COLUMNS: usize = 8;

/// Every kernel's [`Kernel::row_block`] divides this: storage comes in whole blocks of rows.
pub const ROW_BLOCK: usize = 2;

const _: () = {
    let mut i = 0;
    while i < Kernel::ALL.len() {
        assert!(ROW_BLOCK.is_multiple_of(Kernel::ALL[i].row_block()));
        i += 1;
    }
};

/// An implementation of the resonator recursion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// One mode at a time: the reference the others are tested against.
    Scalar,
    /// Arrays the compiler vectorises for the baseline target (SSE2 on x86-64).
    Portable,
    /// AVX2 + FMA intrinsics.
    Avx2,
    /// AVX-512 (F + DQ) intrinsics.
    Avx512,
}

impl Kernel {
    /// Every kernel, in order of increasing width.
    pub const ALL: [Kernel; 4] = [
        Kernel::Scalar,
        Kernel::Portable,
        Kernel::Avx2,
        Kernel::Avx512,
    ];

    /// The fastest kernel this CPU runs.
    pub fn detect() -> Self {
        [Kernel::Avx512, Kernel::Avx2]
            .into_iter()
            .find(|k| k.is_supported())
            .unwrap_or(Kernel::Portable)
    }

    /// The kernel named by the `MODAL_RESONATOR_KERNEL` environment variable when it is set to a
    /// supported one (`scalar`, `portable`, `avx2`, `avx512`), else [`Kernel::detect`].
    pub fn from_env_or_detect() -> Self {
        std::env::var("MODAL_RESONATOR_KERNEL")
            .ok()
            .and_then(|name| Self::from_name(&name))
            .filter(|k| k.is_supported())
            .unwrap_or_else(Self::detect)
    }

    /// The kernel with this lowercase name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name.trim().to_ascii_lowercase())
    }

    /// Lowercase name, as accepted by [`Kernel::from_name`].
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Scalar => "scalar",
            Kernel::Portable => "portable",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
        }
    }

    /// Row counts handed to this kernel are multiples of this: 2 where a vector (AVX-512) or a
    /// group (portable) spans two rows, else 1.
    pub const fn row_block(self) -> usize {
        match self {
            Kernel::Scalar | Kernel::Avx2 => 1,
            Kernel::Portable | Kernel::Avx512 => 2,
        }
    }

    /// Whether this CPU can run the kernel.
    pub fn is_supported(self) -> bool {
        match self {
            Kernel::Scalar | Kernel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"),
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512dq")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }
}

/// The state and coefficients of `rows` rows of modes, structure-of-arrays.
pub struct Rows<'a> {
    /// Real parts of the phasor states.
    pub re: &'a mut [f32],
    /// Imaginary parts of the phasor states: the modes' outputs.
    pub im: &'a mut [f32],
    /// `R cos(theta) - 1` per mode.
    pub q_re: &'a [f32],
    /// `R sin(theta)` per mode.
    pub q_im: &'a [f32],
    /// Input gain per mode.
    pub gain: &'a [f32],
}

/// Advances every mode in `rows` over `acc.len()` samples, driven by `input` when given (same
/// length as `acc`), adding each mode's output to `acc[n][column]`.
///
/// Panics when the slices disagree in length, the row count is not a multiple of the kernel's
/// [`Kernel::row_block`], or `kernel` is not supported by this CPU.
pub fn process(kernel: Kernel, rows: Rows<'_>, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
    let len = rows.re.len();
    assert!(
        rows.im.len() == len
            && rows.q_re.len() == len
            && rows.q_im.len() == len
            && rows.gain.len() == len,
        "resonator slices differ in length"
    );
    let block = kernel.row_block();
    assert_eq!(
        len % (COLUMNS * block),
        0,
        "rows for the {} kernel must come in blocks of {block}",
        kernel.name()
    );
    if let Some(x) = input {
        assert_eq!(x.len(), acc.len(), "input and accumulator lengths differ");
    }
    if len == 0 || acc.is_empty() {
        return;
    }
    match kernel {
        Kernel::Scalar => scalar::process(rows, input, acc),
        Kernel::Portable => portable::process(rows, input, acc),
        #[cfg(target_arch = "x86_64")]
        Kernel::Avx2 => {
            assert!(kernel.is_supported(), "this CPU lacks AVX2 + FMA");
            // SAFETY: the CPU supports AVX2 and FMA (checked above); slice lengths are checked.
            unsafe { x86::process_avx2(rows, input, acc) }
        }
        #[cfg(target_arch = "x86_64")]
        Kernel::Avx512 => {
            assert!(kernel.is_supported(), "this CPU lacks AVX-512 F + DQ");
            // SAFETY: the CPU supports AVX-512 F and DQ (checked above); slice lengths are checked.
            unsafe { x86::process_avx512(rows, input, acc) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        _ => portable::process(rows, input, acc),
    }
}
