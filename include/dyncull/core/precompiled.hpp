/// @file precompiled.hpp
/// Header-only or precompiled use (build plumbing, no paper equation). A translation unit that defines
/// DYNCULL_PRECOMPILED (the dyncull::pipeline library's interface does) gets declarations only of the
/// solvers without a template parameter and of the standard instantiations; that library holds them.
#pragma once

/// Linkage of a solver without a template parameter: inline when header-only, so every translation unit
/// may define it; an ordinary declaration with DYNCULL_PRECOMPILED, defined once in dyncull::pipeline.
#if defined(DYNCULL_PRECOMPILED)
#define DYNCULL_SOLVER
#else
#define DYNCULL_SOLVER inline
#endif

// The mixing rule (docs/design.md): a program takes these solvers either header-only or from
// dyncull::pipeline, never both, since a function inline in one translation unit and not in another makes
// the program ill-formed. On ELF targets built by g++ or clang++ it is a link error: every header-only
// translation unit defines the marker symbols below in one COMDAT group (so header-only units merge), and
// the library's solver objects (src/geometry/) define them too, so a program holding both fails to link
// with "multiple definition of dyncull_abi_fundamental_solvers" (or _pnp_). DYNCULL_UNGUARDED_MIXING turns
// the guard off, for dyncull's own test that compares the two forms in one binary.
#if !defined(DYNCULL_PRECOMPILED) && !defined(DYNCULL_UNGUARDED_MIXING) && defined(__ELF__) && \
    (defined(__GNUC__) || defined(__clang__))
__asm__(".pushsection .data.dyncull_header_only_solvers,\"awG\",%progbits,dyncull_header_only_solvers,comdat\n"
        ".globl dyncull_abi_fundamental_solvers\n"
        ".globl dyncull_abi_pnp_solvers\n"
        "dyncull_abi_fundamental_solvers:\n"
        "dyncull_abi_pnp_solvers:\n"
        ".byte 0\n"
        ".popsection\n");
#endif
