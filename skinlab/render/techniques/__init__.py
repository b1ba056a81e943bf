"""The subsurface techniques, one package each (registered in skinlab/render/registry.py):

  tsd    texture-space diffusion with the Gaussian fit (d'Eon & Luebke 2007), the default
  exact  brute-force texture-space convolution with the exact profile (the slow image reference)
  ssss   screen-space separable SSS (Jimenez et al.)
  tint   the per-pixel profile tint, no convolution (the original study's baseline)
  none   plain Burley diffuse, no subsurface scattering

docs/architecture.md shows how to add one.
"""
