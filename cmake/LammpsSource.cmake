# Locate the LAMMPS source tree and verify it, or obtain Debian's source package.
#
# -D LAMMPS_SOURCE_DIR=<checkout>  use that tree (4Feb2025 or newer; never modified)
# default                          fetch lammps 20250204+dfsg.1-2 from Debian (trixie deb-src)
#                                  into GC_DEPS_DIR (default <repo>/.deps), sha256-checked
# Result: GC_LAMMPS_DIR.
set(LAMMPS_SOURCE_DIR "" CACHE PATH "Root of a LAMMPS checkout (4Feb2025 or newer); empty = Debian source package")
set(GC_DEPS_DIR "${CMAKE_CURRENT_SOURCE_DIR}/.deps" CACHE PATH "Cache folder for the downloaded LAMMPS source")
set(GC_MIN_LAMMPS_VERSION 20250204)

function(gc_check_lammps_tree dir origin)
  set(hint "Give -D LAMMPS_SOURCE_DIR=<root of a LAMMPS 4Feb2025 (or newer) checkout>, or leave it empty to use Debian's source package.")
  foreach(f cmake/CMakeLists.txt cmake/Modules/StyleHeaderUtils.cmake src/version.h
            src/GRANULAR/granular_model.h src/GRANULAR/gran_sub_mod.h python/lammps/core.py)
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
  if(ver LESS GC_MIN_LAMMPS_VERSION)
    message(FATAL_ERROR "LAMMPS in ${dir} is version ${ver}; GRANULAR-CHARGED needs ${GC_MIN_LAMMPS_VERSION} or newer (granular sub-model architecture).\n${hint}")
  endif()
  message(STATUS "LAMMPS source: ${dir} (${origin}, version ${ver})")
endfunction()

if(LAMMPS_SOURCE_DIR)
  get_filename_component(GC_LAMMPS_DIR "${LAMMPS_SOURCE_DIR}" ABSOLUTE)
  gc_check_lammps_tree("${GC_LAMMPS_DIR}" "LAMMPS_SOURCE_DIR")
else()
  execute_process(
    COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/cmake/fetch-lammps-debian.sh ${GC_DEPS_DIR}
    OUTPUT_VARIABLE fetched OUTPUT_STRIP_TRAILING_WHITESPACE
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "Could not obtain the LAMMPS source from Debian (see the step named above). "
                        "Use -D LAMMPS_SOURCE_DIR=/path/to/lammps to build against your own checkout.")
  endif()
  set(GC_LAMMPS_DIR "${fetched}")
  gc_check_lammps_tree("${GC_LAMMPS_DIR}" "Debian source package lammps 20250204+dfsg.1-2")
endif()
