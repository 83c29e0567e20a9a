# The renderer's OpenCL program: every kernel source in program order (each file may use
# what the files before it define; shared/gltf_params.h and device_types.h come first). A new .cl file is
# added here, in the folder of its subsystem; a component of the glTF mixture
# (cl/bsdf/gltf/NAME.cl) between gltf/mixture.cl and bsdf_gltf.cl, after the components it
# uses. The files up to and including cl/bsdf/energy_dielectric.cl (kLastTablesFile,
# host/device/kernel_sources.hpp) also make the tables program, which holds every table
# kernel (energy.cl, sheen.cl, energy_dielectric.cl).
set(CANDELA_CL_SOURCES
  cl/shared/gltf_params.h
  cl/shared/device_types.h
  cl/shared/color.h
  cl/shared/light_profiles.h
  cl/core/rng.cl
  cl/core/sampling.cl
  cl/core/geometry.cl
  cl/accel/intersect.cl
  cl/accel/bvh_traverse.cl
  cl/scene/scene_data.cl
  cl/scene/textures.cl
  cl/camera/filter.cl
  cl/camera/camera.cl
  cl/scene/surface.cl
  cl/scene/alpha.cl
  cl/bsdf/fresnel.cl
  cl/bsdf/microfacet.cl
  cl/bsdf/energy.cl
  cl/bsdf/sheen.cl
  cl/bsdf/dispersion.cl
  cl/bsdf/iridescence.cl
  cl/bsdf/bsdf_common.cl
  cl/bsdf/bsdf_diffuse.cl
  cl/bsdf/bsdf_conductor.cl
  cl/bsdf/bsdf_dielectric.cl
  cl/bsdf/energy_dielectric.cl
  cl/bsdf/gltf/mixture.cl
  cl/bsdf/gltf/fresnel.cl
  cl/bsdf/gltf/coat.cl
  cl/bsdf/gltf/sheen.cl
  cl/bsdf/gltf/metal.cl
  cl/bsdf/gltf/spec.cl
  cl/bsdf/gltf/difftrans.cl
  cl/bsdf/gltf/diffuse.cl
  cl/bsdf/gltf/ms.cl
  cl/bsdf/gltf/glass.cl
  cl/bsdf/bsdf_gltf.cl
  cl/bsdf/bsdf.cl
  cl/bsdf/unlit.cl
  cl/lights/light_common.cl
  cl/lights/environment.cl
  cl/lights/triangle.cl
  cl/lights/punctual.cl
  cl/lights/light_tree.cl
  cl/lights/lights.cl
  cl/media/phase.cl
  cl/media/nanovdb.cl
  cl/media/media.cl
  cl/integrator/aov.cl
  cl/integrator/integrator_path.cl
  cl/integrator/render_paths.cl)
