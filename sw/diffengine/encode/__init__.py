"""Encode: images -> command files that the array decodes (§7.7.2, docs/reconstruction.md).
`image` is `diffengine encode` (loading images, channel encoders, decoding through the
model, PSNR, writing .cmd/.de48); `spline` the multiresolution spline coder; `raster` the
baselines (Eval0 rasters, run lengths, JPEG at matched bytes); `wavelet` the 2-D
spline-wavelet codec (a range-coded file; per-line Eval2 + SetdI programs at decode) with
`entropy` its adaptive binary range coder. A new image codec goes here.
"""
