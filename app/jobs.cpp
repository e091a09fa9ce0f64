#include "app/jobs.h"

#include "app/edit_job.h"
#include "app/joints_job.h"
#include "app/merge_job.h"
#include "app/retarget_job.h"
#include "app/transfer_job.h"

namespace mm::app {

const std::vector<JobSchema>& job_schemas() {
  static const std::vector<JobSchema> jobs = {
      {"edit", edit_options().json(), edit_options().help()},
      {"merge", merge_options().json(), merge_options().help()},
      {"transfer", transfer_options().json(), transfer_options().help()},
      {"transfer-parts", transfer_part_options().json(), transfer_part_options().help()},
      {"retarget", retarget_options().json(), retarget_options().help()},
      {"joints", joints_options().json(), joints_options().help()},
  };
  return jobs;
}

std::string job_names() {
  std::string out;
  for (const JobSchema& j : job_schemas()) out += (out.empty() ? "" : ", ") + j.name;
  return out;
}

}  // namespace mm::app
