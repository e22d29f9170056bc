# Locate the LAMMPS source tree and verify it, or obtain Debian's source package.
#
# -D LAMMPS_SOURCE_DIR=<checkout>  use that tree (a supported release; never modified)
# -D LAMMPS_VERSION=<release>      which Debian source package to fetch when no tree is given:
#                                  20260704 (default, 4Jul2026, sid) or 20250204 (4Feb2025, trixie),
#                                  into GC_DEPS_DIR (default <repo>/.deps), sha256-checked
# Result: GC_LAMMPS_DIR, GC_LAMMPS_VERSION (yyyymmdd of the tree) and the compatibility
# definitions GC_LAMMPS_COMPILE_DEFINITIONS for the package sources (doc/build.md, "Releases"),
# GC_GRAN_SUB_MOD_MECHANISM (style-header or table, cmake/GranSubModRegistry.cmake).
set(GC_SUPPORTED_LAMMPS_VERSIONS 20250204 20260704)    # oldest first, both tested by .ci/run
set(GC_SUPPORTED_LAMMPS_NAMES "4Feb2025 (20250204) and 4Jul2026 (20260704)")
set(LAMMPS_SOURCE_DIR "" CACHE PATH "Root of a LAMMPS checkout (4Feb2025 to 4Jul2026); empty = Debian source package")
set(LAMMPS_VERSION 20260704 CACHE STRING "LAMMPS release fetched from Debian when LAMMPS_SOURCE_DIR is empty")
set_property(CACHE LAMMPS_VERSION PROPERTY STRINGS ${GC_SUPPORTED_LAMMPS_VERSIONS})
include(GranSubModRegistry)
set(GC_DEPS_DIR "${CMAKE_CURRENT_SOURCE_DIR}/.deps" CACHE PATH "Cache folder for the downloaded LAMMPS source")

# Checks a tree before anything is built from it: complete, a supported release, and a
# GRANULAR package whose sub-models are registered the way the overlay needs.
function(gc_check_lammps_tree dir origin)
  set(hint "Supported LAMMPS releases: ${GC_SUPPORTED_LAMMPS_NAMES}. Give -D LAMMPS_SOURCE_DIR=<root of such a checkout>, or leave it empty to use Debian's source package (-D LAMMPS_VERSION=20260704 or 20250204).")
  foreach(f cmake/CMakeLists.txt cmake/Modules/StyleHeaderUtils.cmake src/version.h
            src/GRANULAR/granular_model.h src/GRANULAR/granular_model.cpp
            src/GRANULAR/gran_sub_mod.h src/GRANULAR/gran_sub_mod_twisting.h python/lammps/core.py)
    if(NOT EXISTS "${dir}/${f}")
      message(FATAL_ERROR "LAMMPS source tree ${dir} (${origin}) is missing or incomplete: ${f} not found.\n${hint}")
    endif()
  endforeach()
  file(STRINGS "${dir}/src/version.h" vline REGEX "LAMMPS_VERSION")
  string(REGEX MATCH "\"([0-9]+) ([A-Za-z]+) ([0-9]+)" _ "${vline}")
  set(months Jan Feb Mar Apr May Jun Jul Aug Sep Oct Nov Dec)
  list(FIND months "${CMAKE_MATCH_2}" mon)
  if(mon LESS 0)
    message(FATAL_ERROR "Cannot read the LAMMPS version from ${dir}/src/version.h.\n${hint}")
  endif()
  math(EXPR ver "${CMAKE_MATCH_3} * 10000 + (${mon} + 1) * 100 + ${CMAKE_MATCH_1}")
  list(GET GC_SUPPORTED_LAMMPS_VERSIONS 0 oldest)
  list(GET GC_SUPPORTED_LAMMPS_VERSIONS -1 newest)
  if(ver LESS oldest)
    message(FATAL_ERROR "LAMMPS in ${dir} (${origin}) is version ${ver}, outside the supported range ${oldest} to ${newest}.\n${hint}")
  endif()
  if(ver GREATER newest)
    # the next release (sub-model table, see below) is prepared for but not yet tested
    message(WARNING "LAMMPS version ${ver} is newer than the newest tested release (${GC_SUPPORTED_LAMMPS_NAMES}); building it untested.")
  elseif(NOT ver IN_LIST GC_SUPPORTED_LAMMPS_VERSIONS)
    message(WARNING "LAMMPS version ${ver} lies between the supported releases but is not itself tested (${GC_SUPPORTED_LAMMPS_NAMES}).")
  endif()

  # How the tree registers granular sub-models (cmake/GranSubModRegistry.cmake): the generated
  # style_gran_sub_mod.h (4Feb2025, 4Jul2026: RegisterStyles() adds the package's headers) or
  # the checked-in table gran_sub_mod_register.cpp (development branch: the build compiles a
  # copy with the package's rows instead).
  gc_gran_sub_mod_mechanism("${dir}" mech)
  if(NOT mech)
    message(FATAL_ERROR "LAMMPS in ${dir} (${origin}, version ${ver}) does not register granular "
      "sub-models in a way GRANULAR-CHARGED knows (the generated style_gran_sub_mod.h or the table "
      "src/GRANULAR/gran_sub_mod_register.cpp); found ${mech_WHY}.\n${hint}")
  endif()
  set(GC_GRAN_SUB_MOD_MECHANISM ${mech} PARENT_SCOPE)

  # Compatibility points (one source for both releases): 4Jul2026 changed
  # GranSubModTwisting::calculate_forces() to return the twisting moment instead of storing it.
  file(STRINGS "${dir}/src/GRANULAR/gran_sub_mod_twisting.h" twist REGEX "virtual double calculate_forces")
  set(defs GC_LAMMPS_VERSION=${ver})
  if(twist)
    list(APPEND defs GC_TWISTING_RETURNS_MOMENT=1)
  else()
    list(APPEND defs GC_TWISTING_RETURNS_MOMENT=0)
  endif()
  set(GC_LAMMPS_VERSION ${ver} PARENT_SCOPE)
  set(GC_LAMMPS_COMPILE_DEFINITIONS ${defs} PARENT_SCOPE)
  message(STATUS "LAMMPS source: ${dir} (${origin}, version ${ver})")
endfunction()

if(LAMMPS_SOURCE_DIR)
  get_filename_component(GC_LAMMPS_DIR "${LAMMPS_SOURCE_DIR}" ABSOLUTE)
  gc_check_lammps_tree("${GC_LAMMPS_DIR}" "LAMMPS_SOURCE_DIR")
else()
  if(NOT LAMMPS_VERSION IN_LIST GC_SUPPORTED_LAMMPS_VERSIONS)
    message(FATAL_ERROR "LAMMPS_VERSION=${LAMMPS_VERSION} is not a supported release; supported: ${GC_SUPPORTED_LAMMPS_NAMES}.")
  endif()
  execute_process(
    COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/cmake/fetch-lammps-debian.sh ${GC_DEPS_DIR} ${LAMMPS_VERSION}
    OUTPUT_VARIABLE fetched OUTPUT_STRIP_TRAILING_WHITESPACE
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "Could not obtain the LAMMPS source from Debian (see the step named above). "
                        "Use -D LAMMPS_SOURCE_DIR=/path/to/lammps to build against your own checkout.")
  endif()
  set(GC_LAMMPS_DIR "${fetched}")
  gc_check_lammps_tree("${GC_LAMMPS_DIR}" "Debian source package of LAMMPS ${LAMMPS_VERSION}")
endif()
