# Make LAMMPS's Python module importable from /usr/bin/python3 after the build:
# <build>/python/lammps is a copy of <lammps>/python/lammps with liblammps.so linked beside it
# (the module loads the library from its own folder first), so PYTHONPATH=<build>/python is
# all a user needs; <build>/env.sh sets it (and PATH for lmp).
set(GC_PYTHON_DIR ${CMAKE_BINARY_DIR}/python)
add_custom_target(lammps_python ALL
  COMMAND ${CMAKE_COMMAND} -E copy_directory ${GC_LAMMPS_DIR}/python/lammps ${GC_PYTHON_DIR}/lammps
  COMMAND ${CMAKE_COMMAND} -E create_symlink $<TARGET_FILE:lammps> ${GC_PYTHON_DIR}/lammps/$<TARGET_FILE_NAME:lammps>
  COMMAND ${CMAKE_COMMAND} -E create_symlink $<TARGET_FILE:lammps> ${GC_PYTHON_DIR}/lammps/liblammps.so
  DEPENDS lammps
  COMMENT "Staging LAMMPS Python module in ${GC_PYTHON_DIR}")
file(WRITE ${CMAKE_BINARY_DIR}/env.sh
"# source this file: makes lmp, the lammps Python module and granular_charged available
export PATH=\"${CMAKE_BINARY_DIR}:\$PATH\"
export PYTHONPATH=\"${GC_PYTHON_DIR}:${CMAKE_CURRENT_SOURCE_DIR}/python\${PYTHONPATH:+:\$PYTHONPATH}\"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
")
