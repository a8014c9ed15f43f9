// Redraw on demand: the 3D scene is rendered into an offscreen framebuffer only when something
// it shows changed (camera, viewport, scene data, layer settings, animation); otherwise the
// previous image is copied to the window and only the UI is drawn on top. On a software
// rasterizer (llvmpipe) this turns a 70K-face frame into a single blit while nothing moves.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "render/gl_util.h"
#include "render/layers.h"

namespace qs::render {

//! FNV-1a hash over the bytes of trivially copyable values and vectors of them. Used to
//! summarize everything a frame of the scene depends on in one 64-bit key.
class FrameKey {
 public:
  void add_bytes(const void* data, std::size_t bytes);
  template <class T>
  void add(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "hash trivially copyable values only");
    add_bytes(&value, sizeof(T));
  }
  template <class T>
  void add(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>, "hash trivially copyable values only");
    add(values.size());
    if (!values.empty()) add_bytes(values.data(), values.size() * sizeof(T));
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 1469598103934665603ull;
};

//! Adds every field of \p scene that changes what the layers draw: pointers, versions, ids,
//! the preview / stroke polylines, issue lists and pin overrides (all small).
void add_scene(FrameKey& key, const SceneData& scene);

//! An offscreen colour + depth framebuffer with the window's sample count, holding the last
//! rendered scene. All calls on the GL thread.
class SceneCache {
 public:
  SceneCache() = default;
  ~SceneCache();
  SceneCache(const SceneCache&) = delete;
  SceneCache& operator=(const SceneCache&) = delete;

  //! Prepares a frame of \p width x \p height pixels whose scene is summarized by \p key.
  //! Returns true when the scene must be rendered: the cache's framebuffer is then bound
  //! (draw and read) and the caller draws the scene into render_size() pixels (the lower left
  //! corner), then calls end(). Returns false when the cached image is still valid. When
  //! offscreen rendering is unavailable (incomplete framebuffer) it returns true with the
  //! window framebuffer bound (no caching, full size).
  //! \p scale in (0, 1]: render at this fraction of the size and stretch the image to the window
  //! when presenting (a cheaper image while the camera moves). Only without multisampling
  //! (a multisampled image cannot be stretched); otherwise 1 is used.
  bool begin(int width, int height, std::uint64_t key, float scale = 1.0f);
  //! Size in pixels the scene is drawn at in the current frame (after begin()).
  int render_width() const { return render_width_; }
  int render_height() const { return render_height_; }
  //! After a render started by begin(): binds the window framebuffer again.
  void end();
  //! Copies the cached image to the window framebuffer (colour only). No-op without a cache.
  void present();
  //! Forgets the cached image (the next begin() renders).
  void invalidate() { valid_ = false; }
  //! False after an incomplete framebuffer: every frame is drawn directly.
  bool enabled() const { return enabled_; }
  void set_enabled(bool enabled) {
    enabled_ = enabled;
    valid_ = false;
  }
  //! Deletes the GL objects (call while the context is current; the destructor does it too).
  void release();
  //! Sample count of the offscreen framebuffer (the window's).
  int samples() const { return samples_; }

 private:
  bool allocate(int width, int height);

  GLuint fbo_ = 0;
  GLuint color_ = 0;  // renderbuffer
  GLuint depth_ = 0;  // renderbuffer
  int width_ = 0;
  int height_ = 0;
  int render_width_ = 0;  // part of the framebuffer holding the image (scaled frames)
  int render_height_ = 0;
  int samples_ = 0;
  bool enabled_ = true;
  bool valid_ = false;
  bool bound_ = false;
  std::uint64_t key_ = 0;
};

}  // namespace qs::render
