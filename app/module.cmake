# app: the jobs tier (one job per workflow: read inputs, run, write outputs, report) and the
# options schema of each job, shared by the CLI (native/), the wasm bindings (wasm/) and bench/.
list(APPEND MM_CORE_SOURCES
  app/option_schema.cpp
  app/transfer_job.cpp
  app/edit_spec.cpp
  app/edit_job.cpp
  app/retarget_job.cpp
  app/joints_job.cpp
  app/merge_job.cpp
  app/jobs.cpp
  app/batch_manifest.cpp
  app/batch_state.cpp
  app/batch_worker.cpp
  app/batch_run.cpp)
list(APPEND MM_TEST_SOURCES tests/app_test.cpp tests/batch_test.cpp tests/retarget_checks_test.cpp)
# Batch job keys include the program version (a new version re-runs every job).
set_source_files_properties(app/batch_state.cpp PROPERTIES COMPILE_DEFINITIONS MM_PROGRAM_VERSION="${PROJECT_VERSION}")
# `meshmorph batch` (native/commands/batch.cpp) is built by native/CMakeLists.txt's
# commands/<module>.cpp rule: batch counts as a module of this tier there.
if(NOT "batch" IN_LIST MM_MODULES)
  list(APPEND MM_MODULES batch)
endif()
# End to end on a private single-node Slurm (tests/batch_slurm.sh): skipped (77) unless slurm-wlm
# and munge are installed and the tests run as root.
if(NOT EMSCRIPTEN)
  add_test(NAME batch_slurm COMMAND ${PROJECT_SOURCE_DIR}/tests/batch_slurm.sh $<TARGET_FILE:meshmorph>)
  set_tests_properties(batch_slurm PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600)
endif()
