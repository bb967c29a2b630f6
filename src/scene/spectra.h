// Converts the ways a pbrt-v4 file states a spectrum (rgb, blackbody, named spectra, inline
// wavelength/value pairs, spectrum files) into a SpectrumCurve. How a value is read depends on
// what it describes, as in pbrt-v4: reflectances are bounded by 1, unbounded values (eta, k) are
// taken as they are, and light spectra other than rgb are normalised to unit luminance (pbrt-v4
// divides light spectra by their photometric value; an rgb light keeps its magnitude).
#pragma once
#include <optional>
#include <string>

#include "base/color.h"
#include "scene/params.h"

namespace bpm {

// nullopt when the parameter is absent. Throws Error (with the parameter's location) for a bad
// value: negative, reflectance above 1, unknown named spectrum, unreadable file. A spectrum file
// read is appended to *files_read when given.
std::optional<SpectrumCurve> get_spectrum(const ParamSet& ps, const std::string& name,
                                          SpectrumKind kind, const std::string& directory,
                                          std::vector<std::string>* files_read = nullptr);

// A named pbrt-v4 spectrum as it is stored (not normalised); nullopt when the name is unknown.
std::optional<SpectrumCurve> named_spectrum(const std::string& name, SpectrumKind kind);

}  // namespace bpm
