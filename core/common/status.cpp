#include "common/status.h"

namespace mm {

const char* status_code_name(StatusCode code) {
  switch (code) {
    case StatusCode::Ok: return "Ok";
    case StatusCode::InvalidArgument: return "InvalidArgument";
    case StatusCode::InvalidMesh: return "InvalidMesh";
    case StatusCode::IoError: return "IoError";
    case StatusCode::ParseError: return "ParseError";
    case StatusCode::Unsupported: return "Unsupported";
    case StatusCode::FactorizationFailed: return "FactorizationFailed";
    case StatusCode::NotConverged: return "NotConverged";
    case StatusCode::NumericalError: return "NumericalError";
    case StatusCode::Cancelled: return "Cancelled";
  }
  return "Unknown";
}

}  // namespace mm
