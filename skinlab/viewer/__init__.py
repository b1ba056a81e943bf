"""Desktop viewer (`skinlab view`): a pyglet window showing the renderer's passes, with orbit
camera, Dear ImGui parameter panel, pass inspector and hot reload of shaders, scene and presets.

Window-independent parts (camera math, panel model, file watching, inspector, ViewerCore) import
neither pyglet nor imgui, so they are tested headless."""
