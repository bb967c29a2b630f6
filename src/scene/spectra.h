// Converts the ways a pbrt-v4 file states a spectrum (rgb, blackbody, named spectra, inline
// wavelength/value pairs, spectrum files) into bpm's RGB Spectrum. How a value is read depends on
// what it describes, as in pbrt-v4: reflectances are bounded by 1, illuminants are normalised to
// unit luminance (pbrt-v4 divides light spectra by their photometric value), unbounded values
// (eta, k) are taken as they are.
#pragma once
#include <optional>
#include <string>

#include "base/spectrum.h"
#include "scene/params.h"

namespace bpm {

enum class SpectrumKind { kAlbedo, kUnbounded, kIlluminant };

// nullopt when the parameter is absent. Throws Error (with the parameter's location) for a bad
// value: negative, reflectance above 1, unknown named spectrum, unreadable file.
std::optional<Spectrum> get_spectrum(const ParamSet& ps, const std::string& name, SpectrumKind kind,
                                     const std::string& directory);

// RGB of a named pbrt-v4 spectrum; nullopt when the name is unknown.
std::optional<Spectrum> named_spectrum_rgb(const std::string& name, SpectrumKind kind);

// Linear sRGB of a blackbody at temperature_kelvin, scaled to unit luminance.
Spectrum blackbody_rgb(float temperature_kelvin);

// Linear sRGB of a piecewise-linear spectrum given as (wavelength nm, value) pairs.
Spectrum sampled_spectrum_rgb(const std::vector<double>& lambda_value_pairs, SpectrumKind kind);

}  // namespace bpm
