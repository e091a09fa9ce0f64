// Every job of the app tier by name, with its options schema (JSON for the page and `meshmorph
// options --json`, help text for the CLI). One list, read by the CLI and the wasm module.
#pragma once

#include <string>
#include <vector>

namespace mm::app {

struct JobSchema {
  std::string name;  // "edit", "merge", "transfer", "retarget"
  std::string json;  // OptionSchema::json()
  std::string help;  // OptionSchema::help()
};

const std::vector<JobSchema>& job_schemas();
// The job names joined for messages: "edit, merge, transfer, retarget".
std::string job_names();

}  // namespace mm::app
