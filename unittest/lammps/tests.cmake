# one gc_lammps_test() per test file; see ../CMakeLists.txt
gc_lammps_test(test_jkr_marshall SOURCES test_jkr_marshall.cpp)
gc_lammps_test(test_jkr_marshall_reproducible NP 1 2 SOURCES test_jkr_marshall_reproducible.cpp)
# its restart is read by a separate lmp process
target_compile_definitions(test_jkr_marshall_reproducible PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>")
add_dependencies(test_jkr_marshall_reproducible lmp)
gc_lammps_test(test_coul_fmm NP 1 2 SOURCES test_coul_fmm.cpp)
# keyword solver distributed on 1, 2 and 3 ranks (3 oversubscribed on 2 cores)
gc_lammps_test(test_coul_fmm_distributed NP 1 2 3 SOURCES test_coul_fmm_distributed.cpp)
# fix coul/fmm's time stepping alone (no LAMMPS instance)
gc_lammps_test(test_coul_fmm_time_stepping SOURCES test_coul_fmm_time_stepping.cpp)
# charge changes absorbed between evaluations (keyword qchange), on 1 and 2 ranks
gc_lammps_test(test_coul_fmm_absorb NP 1 2 SOURCES test_coul_fmm_absorb.cpp)
gc_lammps_test(test_packing_computes NP 1 2 SOURCES test_packing_computes.cpp)
gc_lammps_test(test_granular_opt NP 1 2 SOURCES test_granular_opt.cpp)
target_compile_definitions(test_granular_opt PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>")
add_dependencies(test_granular_opt lmp)
gc_lammps_test(test_sleep_gran NP 1 2 SOURCES test_sleep_gran.cpp)
# keywords efield, polarize, electrode (gcfmm::PolarizableSolver through the fix)
gc_lammps_test(test_coul_fmm_polarize NP 1 2 SOURCES test_coul_fmm_polarize.cpp)
gc_lammps_test(test_wall_gran_opt NP 1 2 SOURCES test_wall_gran_opt.cpp)
# which sleepers fix sleep/gran wakes, on every processor grid of 1, 2 and 3 ranks
gc_lammps_test(test_sleep_wake NP 1 2 3 SOURCES test_sleep_wake.cpp)
# fix sleep/gran with granular and granular/opt: the same trajectory, on 1 and 3 ranks
gc_lammps_test(test_sleep_styles NP 1 3 SOURCES test_sleep_styles.cpp)
# warnings for inputs LAMMPS accepts that give another answer than meant (read from the log)
gc_lammps_test(test_silent_mistakes NP 1 2 SOURCES test_silent_mistakes.cpp)
gc_lammps_test(test_granular_opt_switch SOURCES test_granular_opt_switch.cpp)
target_compile_definitions(test_granular_opt_switch PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>")
add_dependencies(test_granular_opt_switch lmp)
# fix coul/fmm refuses non-finite charges and unreachable accuracies (one rank: a bad charge
# stops the rank that owns it)
gc_lammps_test(test_coul_fmm_input_checks SOURCES test_coul_fmm_input_checks.cpp)
# the Marshall contacts in SIMD lanes against the scalar kernel on every path the CPU has, and
# a bed run with GCSIMD_MAX_PATH=generic against the default path (separate lmp processes: the path
# is chosen once per process). Bit for bit, so compiled as marshall_lanes.cpp is.
gc_lammps_test(test_marshall_lanes SOURCES test_marshall_lanes.cpp)
target_include_directories(test_marshall_lanes PRIVATE ${CMAKE_SOURCE_DIR}/src/simd/include)
target_compile_options(test_marshall_lanes PRIVATE ${GCSIMD_BITWISE_OPTIONS} -Wno-psabi)
target_compile_definitions(test_marshall_lanes PRIVATE GC_LMP_EXECUTABLE="$<TARGET_FILE:lmp>"
                           GC_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
add_dependencies(test_marshall_lanes lmp)
# granular/opt's contact list kept between neighbor-list builds against granular: contacts made
# and broken between builds, radii changed by fix adapt and by set between runs
gc_lammps_test(test_granular_opt_contact_list NP 1 2 SOURCES test_granular_opt_contact_list.cpp)
# fix tribo/charge against the condenser model's closed forms, charge conservation on 1 and 2 ranks
gc_lammps_test(test_tribo_charge NP 1 2 SOURCES test_tribo_charge.cpp)
# fix bury/gran: the same trajectory without the buried sleepers, their contact histories kept,
# the input checks; on 1 and 2 ranks
gc_lammps_test(test_bury_gran NP 1 2 SOURCES test_bury_gran.cpp)
# fix sleep/gran pairs awake: granular/opt leaves out the pairs of two sleepers, side by side
# with pairs all step by step, on 1 and 2 ranks
gc_lammps_test(test_sleep_pairs NP 1 2 SOURCES test_sleep_pairs.cpp)
