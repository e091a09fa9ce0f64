# app: the jobs tier (one job per workflow: read inputs, run, write outputs, report) and the
# options schema of each job, shared by the CLI (native/), the wasm bindings (wasm/) and bench/.
list(APPEND MM_CORE_SOURCES
  app/option_schema.cpp
  app/transfer_job.cpp
  app/edit_spec.cpp
  app/edit_job.cpp
  app/retarget_job.cpp
  app/merge_job.cpp
  app/jobs.cpp)
list(APPEND MM_TEST_SOURCES tests/app_test.cpp)
