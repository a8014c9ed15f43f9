// What the 3D view shows, gathered from the editor state (GL-free): the mesh, the edited
// layout or the job result shown instead, validation problems, selection, hover, previews.
#pragma once

#include "app/gui/editor.h"
#include "app/gui/tools.h"
#include "render/layers.h"

namespace qs::app {

//! The scene of this frame. Pointers refer into \p editor (valid until it changes).
render::SceneData build_scene(Editor& editor, const Tools& tools);

}  // namespace qs::app
