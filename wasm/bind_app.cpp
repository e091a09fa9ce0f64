// Bindings of the jobs tier (app/): the options schema of each job, from which the page builds its
// options panels (the same schema gives the CLI its flags and --help, see app/option_schema.h).
//
// JS API:
//   optionSchema(job: "edit" | "merge" | "transfer" | "retarget" | "joints")  (app/jobs.h)
//     → {ok, schema: {job, summary, options: [{name, kind, default, min?, max?, choices?, flag, help}]}}
#include <string>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "app/jobs.h"
#include "convert.h"
#include "guard.h"

namespace mm::wasm {
namespace {

emscripten::val option_schema_js(const std::string& job) {
  std::string json;
  for (const app::JobSchema& j : app::job_schemas())
    if (j.name == job) json = j.json;
  if (json.empty())
    return status_object(Status::error(StatusCode::InvalidArgument,
                                       "no job named '" + job.substr(0, 40) + "' (" + app::job_names() + ")"));
  emscripten::val out = status_object(Status::success());
  out.set("schema", emscripten::val::global("JSON").call<emscripten::val>("parse", json));
  return out;
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_app) { bind<&option_schema_js>("optionSchema"); }

}  // namespace mm::wasm
