// Bindings of the jobs tier (app/): the options schema of each job, from which the page builds its
// options panels (the same schema gives the CLI its flags and --help, see app/option_schema.h).
//
// JS API:
//   optionSchema(job: "edit" | "merge" | "transfer" | "retarget" | "joints")  (app/jobs.h)
//     → {ok, schema: {job, summary, options: [{name, kind, default, min?, max?, choices?, flag, help}]}}
//   threads() → {ok, threaded: bool (the -pthread link), maxThreads: n}   (common/threads.h)
//   setMaxThreads(n: int) → the same object; n ≥ 1 caps the core's threads (1 = sequential,
//     bit-identical results either way), n ≤ 0 restores the default (hardware concurrency)
#include <string>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "app/jobs.h"
#include "common/threads.h"
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

emscripten::val threads_js() {
  emscripten::val out = status_object(Status::success());
  out.set("threaded", threads_supported());
  out.set("maxThreads", max_threads());
  return out;
}

emscripten::val set_max_threads_js(int n) {
  set_max_threads(n);
  return threads_js();
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_app) {
  bind<&option_schema_js>("optionSchema");
  bind<&threads_js>("threads");
  bind<&set_max_threads_js>("setMaxThreads");
}

}  // namespace mm::wasm
