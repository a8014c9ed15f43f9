#include "app/gui/actions.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>  // key codes only

#include <algorithm>
#include <filesystem>
#include <limits>

namespace qs::app {

namespace fs = std::filesystem;

KeyBinding key_binding(int key, int mods) {
  const bool ctrl = mods & GLFW_MOD_CONTROL;
  const bool shift = mods & GLFW_MOD_SHIFT;
  if (ctrl) {
    switch (key) {
      case GLFW_KEY_Z:
        return {shift ? Action::Redo : Action::Undo};
      case GLFW_KEY_Y:
        return {Action::Redo};
      case GLFW_KEY_O:
        return {Action::Open};
      case GLFW_KEY_S:
        return {shift ? Action::SaveAs : Action::Save};
      case GLFW_KEY_KP_1:
        return {Action::ViewBack};
      case GLFW_KEY_KP_3:
        return {Action::ViewLeft};
      case GLFW_KEY_KP_7:
        return {Action::ViewBottom};
      default:
        return {};
    }
  }
  switch (key) {
    case GLFW_KEY_F:
    case GLFW_KEY_KP_DECIMAL:
      return {Action::FrameSelected};
    case GLFW_KEY_HOME:
      return {Action::FrameAll};
    case GLFW_KEY_R:
      return {Action::ResetView};
    case GLFW_KEY_DELETE:
    case GLFW_KEY_BACKSPACE:
      return {Action::DeleteSelection};
    case GLFW_KEY_P:
      return {Action::TogglePin};
    case GLFW_KEY_ESCAPE:
      return {Action::Escape};
    case GLFW_KEY_KP_1:
      return {Action::ViewFront};
    case GLFW_KEY_KP_3:
      return {Action::ViewRight};
    case GLFW_KEY_KP_7:
      return {Action::ViewTop};
    case GLFW_KEY_KP_5:
      return {Action::ToggleOrthographic};
    case GLFW_KEY_KP_4:
      return {Action::OrbitLeft};
    case GLFW_KEY_KP_6:
      return {Action::OrbitRight};
    case GLFW_KEY_KP_8:
      return {Action::OrbitUp};
    case GLFW_KEY_KP_2:
      return {Action::OrbitDown};
    default:
      break;
  }
  if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && key - GLFW_KEY_1 < kToolCount)
    return {Action::SetTool, key - GLFW_KEY_1};
  if (key == GLFW_KEY_0 && kToolCount >= 10) return {Action::SetTool, 9};
  return {};
}

int key_from_name(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'A' && name[0] <= 'Z') return GLFW_KEY_A + (name[0] - 'A');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name.size() == 4 && name.rfind("KP_", 0) == 0 && name[3] >= '0' && name[3] <= '9')
    return GLFW_KEY_KP_0 + (name[3] - '0');
  static const std::pair<const char*, int> kNamed[] = {
      {"KP_DECIMAL", GLFW_KEY_KP_DECIMAL}, {"HOME", GLFW_KEY_HOME},     {"DELETE", GLFW_KEY_DELETE},
      {"BACKSPACE", GLFW_KEY_BACKSPACE},   {"ESCAPE", GLFW_KEY_ESCAPE}, {"ENTER", GLFW_KEY_ENTER},
  };
  for (const auto& [n, k] : kNamed)
    if (name == n) return k;
  return -1;
}

void fit_camera_to_mesh(AppContext& ctx, bool reset, bool immediate) {
  if (!ctx.editor.doc.mesh) return;
  Vec3 c;
  double r = 1.0;
  ctx.editor.doc.bounds(c, r);
  ctx.camera.set_scene({float(c[0]), float(c[1]), float(c[2])}, float(r));
  if (reset) ctx.camera.reset(immediate);
}

void focus_vertices(AppContext& ctx, const std::vector<int>& vertices) {
  const TriMesh* mesh = ctx.editor.doc.mesh.get();
  if (!mesh) return;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  int count = 0;
  Vec3 normal(0, 0, 0);
  for (int v : vertices) {
    if (v < 0 || v >= int(mesh->n_vertices())) continue;
    const auto& p = mesh->point(OpenMesh::VertexHandle(v));
    const glm::vec3 q{float(p[0]), float(p[1]), float(p[2])};
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
    ++count;
    // Look from the side the vertices face (area-weighted normals of their faces).
    for (auto fh : mesh->vf_range(OpenMesh::VertexHandle(v))) {
      auto it = mesh->cfv_begin(fh);
      const Vec3 a = mesh->point(*it++), b = mesh->point(*it++), c = mesh->point(*it);
      normal += OpenMesh::cross(b - a, c - a);
    }
  }
  if (count == 0) return;
  ctx.camera.focus(0.5f * (lo + hi), 0.5f * glm::length(hi - lo),
                   glm::vec3(float(normal[0]), float(normal[1]), float(normal[2])));
}

void frame_selected(AppContext& ctx) {
  const Editor& editor = ctx.editor;
  const Layout& layout = editor.doc.editor.layout();
  const int n = layout.node_index(editor.selection.node);
  const int a = layout.arc_index(editor.selection.arc);
  if (editor.selection.node >= 0 && n >= 0) {
    focus_vertices(ctx, {layout.nodes[n].vertex});
  } else if (editor.selection.arc >= 0 && a >= 0) {
    focus_vertices(ctx, layout.arcs[a].path);
  } else if (editor.highlighted_issue >= 0 &&
             editor.highlighted_issue < int(editor.doc.validation.issues.size())) {
    focus_vertices(ctx, editor.doc.validation.issues[editor.highlighted_issue].vertices);
  } else {
    ctx.camera.frame_all();
  }
}

void open_dialog(AppContext& ctx) {
  const std::string start =
      !ctx.editor.doc.mesh_path.empty() && !ctx.editor.is_bundled(ctx.editor.doc.mesh_path)
          ? ctx.editor.doc.mesh_path
          : (ctx.editor.recent.meshes().empty() ? home_folder()
                                                : ctx.editor.recent.meshes().front());
  ctx.ui.browser.open(BrowserMode::Open, start);
}

void save_as_dialog(AppContext& ctx) {
  if (!ctx.editor.doc.mesh) {
    ctx.editor.set_status("Nothing to save: no mesh is open");
    return;
  }
  ctx.ui.browser.open(BrowserMode::Save, ctx.editor.save_path.empty()
                                             ? ctx.editor.default_save_path()
                                             : ctx.editor.save_path);
}

void save_or_ask(AppContext& ctx) {
  if (!ctx.editor.quick_save()) save_as_dialog(ctx);
}

bool accept_browser(AppContext& ctx) {
  FileBrowser& browser = ctx.ui.browser;
  const std::string path = browser.chosen_path();
  if (path.empty()) return false;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {  // a folder typed into the name field: go there
    browser.navigate(path);
    browser.set_file_name("");
    return false;
  }
  bool ok = false;
  if (browser.mode() == BrowserMode::Save) {
    ok = ctx.editor.save(path);
  } else {
    ok = ctx.editor.open_file(path);
    if (ok && is_mesh_file(path)) {
      ctx.ui.mesh_field = path;
      ctx.ui.layout_field.clear();
    } else if (ok) {
      ctx.ui.layout_field = path;
    }
  }
  if (ok) browser.close();
  return ok;
}

void perform(const KeyBinding& binding, AppContext& ctx) {
  Editor& editor = ctx.editor;
  switch (binding.action) {
    case Action::None:
      break;
    case Action::Undo:
      editor.undo();
      ctx.tools.sync(editor);
      break;
    case Action::Redo:
      editor.redo();
      ctx.tools.sync(editor);
      break;
    case Action::Open:
      open_dialog(ctx);
      break;
    case Action::Save:
      save_or_ask(ctx);
      break;
    case Action::SaveAs:
      save_as_dialog(ctx);
      break;
    case Action::SetTool:
      if (binding.tool >= 0 && binding.tool < kToolCount) ctx.tools.set_tool(Tool(binding.tool));
      break;
    case Action::DeleteSelection:
      editor.delete_selection();
      ctx.tools.sync(editor);
      break;
    case Action::TogglePin:
      editor.toggle_pin_selection();
      break;
    case Action::Escape:
      ctx.tools.escape(editor);
      break;
    case Action::FrameSelected:
      frame_selected(ctx);
      break;
    case Action::FrameAll:
      ctx.camera.frame_all();
      break;
    case Action::ResetView:
      ctx.camera.reset();
      break;
    case Action::ViewFront:
      ctx.camera.set_axis_view(render::AxisView::Front);
      break;
    case Action::ViewBack:
      ctx.camera.set_axis_view(render::AxisView::Back);
      break;
    case Action::ViewRight:
      ctx.camera.set_axis_view(render::AxisView::Right);
      break;
    case Action::ViewLeft:
      ctx.camera.set_axis_view(render::AxisView::Left);
      break;
    case Action::ViewTop:
      ctx.camera.set_axis_view(render::AxisView::Top);
      break;
    case Action::ViewBottom:
      ctx.camera.set_axis_view(render::AxisView::Bottom);
      break;
    case Action::ToggleOrthographic:
      ctx.camera.set_orthographic(!ctx.camera.orthographic());
      editor.set_status(ctx.camera.orthographic() ? "Orthographic view" : "Perspective view");
      break;
    // The camera moves around the target: left turns the scene to the right, up looks from
    // higher.
    case Action::OrbitLeft:
      ctx.camera.orbit_step(15.0f, 0.0f);
      break;
    case Action::OrbitRight:
      ctx.camera.orbit_step(-15.0f, 0.0f);
      break;
    case Action::OrbitUp:
      ctx.camera.orbit_step(0.0f, 15.0f);
      break;
    case Action::OrbitDown:
      ctx.camera.orbit_step(0.0f, -15.0f);
      break;
  }
}

}  // namespace qs::app
