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
