// The editor's state as JSON (GL-free), for tests and scripts (--state-json, the script's
// "state" command): the document, the job and the result shown, the selection and the tool,
// the camera, the status bar's texts, the file browser and the autosave offer.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "app/gui/context.h"

namespace qs::app {

//! The state of \p ctx; \p frames: frames drawn so far (0 without a window).
nlohmann::json state_json(AppContext& ctx, int frames);
//! Writes state_json() to \p path (atomically). False with \p error on failure.
bool write_state_json(AppContext& ctx, int frames, const std::string& path, std::string* error);

}  // namespace qs::app
