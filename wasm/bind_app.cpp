// Bindings of the jobs tier (app/): the options schema of each job, from which the page builds its
// options panels (the same schema gives the CLI its flags and --help, see app/option_schema.h).
//
// JS API:
//   optionSchema(job: "edit" | "transfer" | "retarget")
//     → {ok, schema: {job, summary, options: [{name, kind, default, min?, max?, choices?, flag, help}]}}
#include <string>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "app/edit_job.h"
#include "app/retarget_job.h"
#include "app/transfer_job.h"
#include "convert.h"
#include "guard.h"

namespace mm::wasm {
namespace {

emscripten::val option_schema_js(const std::string& job) {
  std::string json;
  if (job == "edit") json = app::edit_options().json();
  else if (job == "transfer") json = app::transfer_options().json();
  else if (job == "retarget") json = app::retarget_options().json();
  else
    return status_object(Status::error(StatusCode::InvalidArgument,
                                       "no job named '" + job.substr(0, 40) + "' (edit, transfer, retarget)"));
  emscripten::val out = status_object(Status::success());
  out.set("schema", emscripten::val::global("JSON").call<emscripten::val>("parse", json));
  return out;
}

}  // namespace

EMSCRIPTEN_BINDINGS(meshmorph_app) { bind<&option_schema_js>("optionSchema"); }

}  // namespace mm::wasm
