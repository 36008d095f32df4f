//! The x86-64 floating-point control and status register, MXCSR: its sticky exception
//! flags DE (a denormal operand was read, bit 1) and UE (a result underflowed, bit 4), and
//! the modes DAZ (read denormal operands as zero, bit 6) and FTZ (flush tiny results to
//! zero, bit 15). The flags are architectural, so a test of them sees on any x86-64 CPU
//! what costs an Intel core a microcode assist.
#![allow(dead_code)]

use core::hint::black_box;

/// Denormal operand flag.
pub const DE: u32 = 1 << 1;
/// Underflow flag.
pub const UE: u32 = 1 << 4;
/// Denormals-are-zero mode.
pub const DAZ: u32 = 1 << 6;
/// Flush-to-zero mode.
pub const FTZ: u32 = 1 << 15;
/// The six sticky exception flags (IE, DE, ZE, OE, UE, PE).
const FLAGS: u32 = 0x3f;

fn read() -> u32 {
    let mut csr = 0u32;
    // SAFETY: `stmxcsr` stores the 32-bit MXCSR to the address of `csr`, a valid, aligned
    // and writable local; SSE is part of the x86-64 baseline, and nothing else changes.
    unsafe {
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack, preserves_flags));
    }
    csr
}

fn write(csr: u32) {
    // SAFETY: `ldmxcsr` loads MXCSR from the address of `csr`, a valid local. Every value
    // written here is a value read from MXCSR with only the sticky flags and the FTZ and
    // DAZ modes changed: no reserved bit is set (which would fault) and the exception
    // masks are untouched, so no floating-point exception can trap. MXCSR is per thread,
    // and `run` restores it before returning.
    unsafe {
        core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack, preserves_flags, readonly));
    }
}

/// Runs `f(input)` with the exception flags cleared and the modes `modes` (a combination
/// of [`FTZ`] and [`DAZ`], or 0) set, then restores MXCSR as it was. Returns what `f`
/// returned and the exception flags raised while it ran.
///
/// The input and the result pass through `black_box`, so the computation can be moved
/// neither before the flags are cleared nor after they are read.
pub fn run<I, R>(modes: u32, input: I, f: impl FnOnce(I) -> R) -> (R, u32) {
    let saved = read();
    write((saved & !(FLAGS | FTZ | DAZ)) | modes);
    let result = black_box(f(black_box(input)));
    let raised = read() & FLAGS;
    write(saved);
    (result, raised)
}

/// The names of the flags set in `flags`, for messages.
pub fn names(flags: u32) -> String {
    let all = [
        (1, "IE"),
        (DE, "DE"),
        (4, "ZE"),
        (8, "OE"),
        (UE, "UE"),
        (32, "PE"),
    ];
    let set: Vec<_> = all
        .iter()
        .filter(|(b, _)| flags & b != 0)
        .map(|(_, n)| *n)
        .collect();
    set.join(" ")
}
