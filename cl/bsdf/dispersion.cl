// KHR_materials_dispersion (CD_FEATURE_DISPERSION): a refracting glTF material's index of
// refraction depends on the wavelength. With `ior` the index at the d line (587.56 nm) and
// the Abbe number V = 20 / dispersion, the extension's linear model is
//   ior(lambda) = max(ior + (ior - 1) / V (523655 / lambda^2 - 1.5168), 1),  lambda in nm.
// Each RGB channel refracts at one representative wavelength: the Fraunhofer lines C
// (656.27 nm, red), d (587.56 nm, green) and F (486.13 nm, blue) that define the Abbe number,
// so n_F - n_C = (ior - 1) / V and the green channel keeps (almost exactly) the material's ior.
// A path is RGB until it meets a dispersive surface; there it picks one channel uniformly,
// multiplies its throughput by 3 x that channel's one-hot (unbiased: the expectation over the
// choice is the RGB throughput) and shades every later surface at that channel's wavelength
// (path_trace, bsdf_at_channel).
#if CD_FEATURE_DISPERSION
// The representative wavelength (nm) of RGB channel c
float dispersion_wavelength(int c) { return c == 0 ? 656.27f : (c == 1 ? 587.56f : 486.13f); }

// The extension's ior at wavelength lambda (nm) of a material of index ior (at the d line)
// and dispersion 20 / V
float dispersion_ior(float ior, float dispersion, float lambda) {
  return fmax(ior + (ior - 1.0f) * (dispersion / 20.0f) * (523655.0f / (lambda * lambda) - 1.5168f), 1.0f);
}

// The material disperses: a glTF material refracting through a volume with dispersion > 0.
// The host leaves GltfMaterial.dispersion 0 on every other material, and the bytes of the
// parameter union there 0 for the other types (compile_materials zero-fills the record)
bool dispersion_material(__global const Material* m) { return m->params.gltf.dispersion > 0.0f; }
#endif
