// Shared by the editor tests that drive qs::app::Editor without a window (GL-free): the
// editor's configuration for tests and polling until a condition holds.
#pragma once

#include <chrono>
#include <functional>
#include <thread>

#include "app/gui/editor.h"
#include "app/gui/job_control.h"

namespace qs::test {

//! An editor configuration for tests: the bundled assets (QS_ASSETS_DIR), solver threads at
//! normal priority, no recent-files list written.
inline app::EditorConfig editor_test_config() {
  app::EditorConfig c;
  c.assets_dir = QS_ASSETS_DIR;
  c.worker_nice = 0;
  c.remember_recent = false;
  c.step = app::editor_step_function(0);
  return c;
}

//! Polls \p editor (Editor::poll, every 2 ms) until \p done returns true or \p timeout passes;
//! false on timeout.
inline bool poll_editor_until(app::Editor& editor, const std::function<bool()>& done,
                              std::chrono::seconds timeout = std::chrono::seconds(120)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    editor.poll();
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

}  // namespace qs::test
