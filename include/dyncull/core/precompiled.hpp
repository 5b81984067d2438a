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

// The mixing rule (docs/design.md): a program takes the solvers either header-only or from dyncull::pipeline,
// never both, since a function inline in one translation unit and not in another makes it ill-formed. On ELF
// targets built by g++ or clang++ breaking it is a link error, and the guard does not depend on which solver
// objects the linker happens to take from the archive:
//  - every header-only translation unit defines the marker symbol below, global, in a COMDAT group of its
//    own, so any number of header-only units merge into one copy;
//  - every precompiled translation unit holds the address of a symbol that only one object of the library
//    defines (src/core/precompiled.cpp, archived in dyncull::pipeline and in dyncull::culler), so linking
//    any precompiled unit always takes that object out of the archive, whatever the header-only units
//    already define (their out-of-line solvers and instantiations satisfy the precompiled unit's calls);
//  - that object defines the marker too, outside any COMDAT group, so a program with both kinds of unit
//    fails with "multiple definition of `dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md'"
//    (GNU ld, gold) or "duplicate symbol: dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md"
//    (lld).
// A precompiled unit linked without the library fails on the reference's name instead. Elsewhere (MSVC,
// Mach-O, other compilers), and across shared libraries (one link step sees one side), the rule holds
// unguarded. DYNCULL_UNGUARDED_MIXING turns the guard off in the translation unit that defines it, for
// dyncull's own test that compares the two forms in one binary.
#if !defined(DYNCULL_UNGUARDED_MIXING) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__))
#if defined(DYNCULL_PRECOMPILED)
extern "C" const char dyncull_precompiled_units_link_dyncull_pipeline_or_culler;
namespace dyncull::detail {
// Internal to each unit and kept by `used` at every optimisation level (sanitizers included): the
// relocation it carries is what makes the linker take src/core/precompiled.cpp's object.
[[gnu::used]] static const char* const precompiled_library_reference =
    &dyncull_precompiled_units_link_dyncull_pipeline_or_culler;
}  // namespace dyncull::detail
#else
__asm__(".pushsection .data.dyncull_header_only_units,\"awG\",%progbits,dyncull_header_only_units,comdat\n"
        ".globl dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md\n"
        "dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md:\n"
        ".byte 0\n"
        ".popsection\n");
#endif
#endif
