"""The subsurface techniques, one package each:

  tsd            texture-space diffusion with the Gaussian fit (d'Eon & Luebke 2007), the default
  exact          brute-force texture-space convolution with the exact profile (the slow image reference)
  ssss           screen-space separable SSS (Jimenez et al.)
  tint           the per-pixel profile tint, no convolution (the original study's baseline)
  none           plain Burley diffuse, no subsurface scattering
  disk           screen-space disk sampling of the exact profile (Golubev 2018)
  preintegrated  pre-integrated skin: a curvature x N.L lookup table (Penner & Borshukov 2011)

``BUILTIN_PACKAGES`` is the one line a new built-in technique adds (docs/architecture.md shows how).
It sits here, below every other module of the renderer, so that turning a technique's name into its
settings (skinlab/render/options.py ``technique_settings``) imports that one package and nothing that
imports the settings back; skinlab/render/registry.py holds the registered techniques.
"""

# name -> package exposing TECHNIQUE, in the order `skinlab render --technique` lists them and the
# viewer's T key goes through them
BUILTIN_PACKAGES: dict[str, str] = {
    "tsd": "skinlab.render.techniques.tsd",
    "exact": "skinlab.render.techniques.exact",
    "ssss": "skinlab.render.techniques.ssss",
    "tint": "skinlab.render.techniques.tint",
    "none": "skinlab.render.techniques.none",
    "disk": "skinlab.render.techniques.disk",
    "preintegrated": "skinlab.render.techniques.preintegrated",
}
DEFAULT_TECHNIQUE = "tsd"
