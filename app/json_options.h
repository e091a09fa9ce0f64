// The "options" object of a JSON spec (edit, merge): every key is an option of the job's schema,
// set exactly as the CLI flag or the page's control of the same name would set it.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "app/option_schema.h"
#include "common/status.h"
#include "io/json_text.h"

namespace mm::app {

// ParseError naming `where` for a non-object, a value that is not a number/string/boolean, an
// unknown option or an out-of-range value.
template <class O>
Status set_options_from_json(const nlohmann::json& obj, const OptionSchema<O>& schema, O* out, const std::string& where) {
  if (!obj.is_object()) return Status::error(StatusCode::ParseError, where + ": options must be an object");
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const nlohmann::json& v = it.value();
    OptionValue value;
    if (v.is_boolean()) value = OptionValue::of_boolean(v.get<bool>());
    else if (v.is_number()) value = OptionValue::of_number(v.get<double>());
    else if (v.is_string()) value = OptionValue::of_text(v.get<std::string>());
    else
      return Status::error(StatusCode::ParseError,
                           where + ": options." + io::quote_input(it.key(), 60) + " must be a number, a string or true/false");
    const Status s = schema.set(*out, it.key(), value);
    if (!s.ok()) return Status::error(StatusCode::ParseError, where + ": " + s.message);
  }
  return Status::success();
}

}  // namespace mm::app
