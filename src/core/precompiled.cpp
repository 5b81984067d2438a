// The library's side of the mixing rule's link guard (core/precompiled.hpp, docs/design.md). Every
// translation unit compiled with DYNCULL_PRECOMPILED refers to the first symbol, which only this object
// defines, so a program with any precompiled unit always links this object; it defines the header-only
// units' marker as well, outside their COMDAT group, so a program that also holds a header-only unit fails
// to link with a multiple definition of that marker.
#ifndef DYNCULL_PRECOMPILED
#define DYNCULL_PRECOMPILED 1
#endif
#include "dyncull/core/precompiled.hpp"

#if !defined(DYNCULL_UNGUARDED_MIXING) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__))
extern "C" {
const char dyncull_precompiled_units_link_dyncull_pipeline_or_culler = 1;
extern const char dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md;
const char dyncull_header_only_and_precompiled_units_mixed_see_docs_design_md = 1;
}
#endif
