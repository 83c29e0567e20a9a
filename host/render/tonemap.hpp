// Display transforms for 8-bit outputs: linear scene radiance -> display-linear [0, 1]
// (the sRGB encoding follows in film.cpp). EXR output stays linear and untouched.
#pragma once

#include <glm/glm.hpp>
#include <string>

#include "base/enum_names.hpp"

namespace candela {

// neutral: Khronos PBR Neutral (made for glTF's base colours: they come out as authored up
//          to highlights, which roll off without hue shifts)
// agx:     AgX with the base contrast look, as Blender 4 defaults to (Rec. 2020 working
//          space, log2 encoding over [-12.47, 4.03] EV, sigmoid contrast curve)
// clamp:   no curve, values above 1 clip
enum class Tonemap { Neutral, Agx, Clamp };

inline constexpr EnumName<Tonemap> kTonemapNames[] = {{Tonemap::Neutral, "neutral", "Khronos PBR Neutral, default"},
                                                      {Tonemap::Agx, "agx", "as Blender 4"},
                                                      {Tonemap::Clamp, "clamp", "no curve"}};

// Throws Error naming the choices for an unknown name
Tonemap parse_tonemap(const std::string& name);
inline const char* tonemap_name(Tonemap t) { return enum_name(kTonemapNames, t); }

// Khronos PBR Neutral tone mapper (Khronos 3D Commerce, 2024): linear sRGB in, [0, 1] out
glm::vec3 tonemap_pbr_neutral(glm::vec3 c);
// AgX (Sobotka 2023; the Blender 4 / Filament form, with its polynomial fit of the
// default contrast sigmoid): linear sRGB in, display-linear [0, 1] out
glm::vec3 tonemap_agx(glm::vec3 c);
glm::vec3 tonemap_apply(Tonemap t, glm::vec3 c);

}  // namespace candela
