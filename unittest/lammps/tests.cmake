# one gc_lammps_test() per test file; see ../CMakeLists.txt
gc_lammps_test(test_jkr_marshall SOURCES test_jkr_marshall.cpp)
gc_lammps_test(test_jkr_marshall_reproducible NP 1 2 SOURCES test_jkr_marshall_reproducible.cpp)
# its restart is read by a separate lmp process
target_compile_definitions(test_jkr_marshall_reproducible PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>")
add_dependencies(test_jkr_marshall_reproducible lmp)
gc_lammps_test(test_coul_fmm NP 1 2 SOURCES test_coul_fmm.cpp)
# fix coul/fmm's time stepping alone (no LAMMPS instance)
gc_lammps_test(test_coul_fmm_time_stepping SOURCES test_coul_fmm_time_stepping.cpp)
gc_lammps_test(test_packing_computes NP 1 2 SOURCES test_packing_computes.cpp)
gc_lammps_test(test_granular_opt NP 1 2 SOURCES test_granular_opt.cpp)
target_compile_definitions(test_granular_opt PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>")
add_dependencies(test_granular_opt lmp)
gc_lammps_test(test_sleep_gran NP 1 2 SOURCES test_sleep_gran.cpp)
