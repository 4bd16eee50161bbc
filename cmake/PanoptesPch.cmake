# Precompiled headers (PANOPTES_PCH, default ON): the heavy header-only libraries, parsed once per target
# instead of once per source file. Measured on 2 idle cores (2026-11-27): a translation unit that only
# includes <CLI/CLI.hpp> (CLI11 2.1, header-only, no compiled mode in Debian 12) costs 7.6 CPU-s at -O2,
# <nlohmann/json.hpp> 2.4 s, <gtest/gtest.h> ~2 s; the `panoptes` program's 121 build steps spent 630
# CPU-s compiling, ~40 % of it in those headers. A new user's first build (scripts/demo) waits for all of it.
option(PANOPTES_PCH "Precompile the heavy third-party headers (CLI11, nlohmann-json, GoogleTest) per target" ON)

# Called once, after every module's directory is added: the targets and which heavy headers they use.
# With unity builds (PANOPTES_UNITY) the libraries and the program parse these headers once per batch
# anyway: measured on 2 idle cores (2026-11-27), the program's fresh build took 150.7 s with these
# precompiled headers and 150.1 s without, so they are only used when unity builds are off.
function(panoptes_precompile_headers)
  if(NOT PANOPTES_PCH OR PANOPTES_FUZZ OR PANOPTES_UNITY)
    return()
  endif()
  # The modules whose sources include the manifest (store/manifest.hpp includes nlohmann/json.hpp) or
  # JSON directly; the hot-loop modules (render, seismic) and the small ones gain nothing.
  foreach(module IN ITEMS camera store insitu player web cinema ui)
    if(TARGET panoptes_${module})
      target_precompile_headers(panoptes_${module} PRIVATE <nlohmann/json.hpp> <string> <vector> <filesystem>)
    endif()
  endforeach()
  # Every command includes app/command.hpp (CLI11) and most read manifests.
  if(TARGET panoptes)
    target_precompile_headers(panoptes PRIVATE <CLI/CLI.hpp> <nlohmann/json.hpp> <string> <vector> <filesystem>)
  endif()
endfunction()

# For one GoogleTest program (panoptes_test): gtest's header is in every test source.
function(panoptes_precompile_test_headers target)
  if(PANOPTES_PCH AND NOT PANOPTES_FUZZ)
    target_precompile_headers(${target} PRIVATE <gtest/gtest.h> <string> <vector>)
  endif()
endfunction()
