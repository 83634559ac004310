// OpenEXR → Rendering: every channel is a slice of one interleaved float buffer, so the chunks decompress straight
// into the Rendering with no copy — flat float ZIP/uncompressed files by exr_flat_read, the rest by OpenEXR's threads.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfPartType.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>

#include <algorithm>
#include <map>
#include <new>
#include <set>

#include "colorlab/core/error.hpp"
#include "exr_flat_read.hpp"
#include "exr_threads.hpp"
#include "io_detail.hpp"

namespace colorlab::verify::detail {

namespace {

struct Layout {
  Encoding encoding = Encoding::xyz;
  bool reflective = false;
  std::vector<std::string> channels;  // in the Rendering's channel order
  std::vector<double> wavelengths_nm;
};

std::string channel_list(const Imf::ChannelList& list) {
  std::string s;
  for (auto it = list.begin(); it != list.end(); ++it) s += (s.empty() ? "" : ", ") + std::string(it.name());
  return s;
}

// The spectral bands of one JCGT layer, sorted by wavelength; a channel in the layer that is not a band name is
// a malformed file, not something to skip silently.
std::vector<std::pair<double, std::string>> layer_bands(const Imf::ChannelList& list, const std::string& layer,
                                                        const std::filesystem::path& file) {
  std::vector<std::pair<double, std::string>> bands;
  const std::string prefix = layer + ".";
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string name = it.name();
    if (name.rfind(prefix, 0) != 0) continue;
    auto nm = spectral_channel_wavelength_nm(name, layer);
    if (!nm)
      bad_data(file, "channel '" + name + "' is in the spectral layer " + layer + " but is not a JCGT band name (e.g. " + layer + ".550,000000nm)",
               "name bands <layer>.<centre with a comma decimal><SI prefix>m or Hz (Fichet et al., JCGT 2021)");
    bands.emplace_back(*nm, name);
  }
  std::sort(bands.begin(), bands.end());
  for (std::size_t i = 1; i < bands.size(); ++i)
    if (bands[i].first - bands[i - 1].first <= 1e-9 * bands[i].first)
      bad_data(file, "channels '" + bands[i - 1].second + "' and '" + bands[i].second + "' name the same band centre");
  return bands;
}

// Spectral first (R,G,B beside it are a preview), then X,Y,Z, then R,G,B.
Layout classify(const Imf::Header& header, const std::filesystem::path& file) {
  const Imf::ChannelList& list = header.channels();
  Layout out;
  for (const char* layer : {"S0", "T"}) {
    auto bands = layer_bands(list, layer, file);
    if (bands.empty()) continue;
    out.encoding = Encoding::spectral;
    out.reflective = std::string(layer) == "T";
    for (auto& [nm, name] : bands) {
      out.wavelengths_nm.push_back(nm);
      out.channels.push_back(name);
    }
    return out;
  }
  for (auto [encoding, names] : {std::pair{Encoding::xyz, std::array<const char*, 3>{"X", "Y", "Z"}},
                                 std::pair{Encoding::rgb, std::array<const char*, 3>{"R", "G", "B"}}}) {
    int present = 0;
    std::string missing;
    for (const char* n : names) {
      if (list.findChannel(n))
        ++present;
      else
        missing += (missing.empty() ? "" : ", ") + std::string(n);
    }
    // Y alone is OpenEXR's luminance image, not an incomplete XYZ one.
    if (present == 3 || (present > 0 && !(encoding == Encoding::xyz && present == 1 && list.findChannel("Y")))) {
      if (present < 3)
        bad_data(file, "channel(s) " + missing + " missing: the file has " + channel_list(list),
                 encoding == Encoding::xyz ? "an XYZ rendering needs X, Y and Z" : "an RGB rendering needs R, G and B");
      out.encoding = encoding;
      out.channels.assign(names.begin(), names.end());
      return out;
    }
  }
  throw Error(ErrorClass::unsupported,
              file.string() + ": OpenEXR channels " + channel_list(list) +
                  " are none of: a JCGT spectral layer (S0.<nm> or T.<nm>), X,Y,Z or R,G,B",
              "write the rendering's radiance as spectral S0 bands, XYZ or RGB (luminance/chroma and layered "
              "multi-pass files are not read)");
}

// The first part holding a rendering: a spectral part wins over XYZ/RGB ones (preview parts beside it).
int choose_part(Imf::MultiPartInputFile& mp, const std::filesystem::path& file) {
  int best = -1;
  for (int p = 0; p < mp.parts(); ++p) {
    const Imf::Header& h = mp.header(p);
    if (h.hasType() && Imf::isDeepData(h.type())) continue;
    try {
      Layout l = classify(h, file);
      if (l.encoding == Encoding::spectral) return p;
      if (best < 0) best = p;
    } catch (const Error& e) {
      if (e.cls() != ErrorClass::unsupported || mp.parts() == 1) throw;
    }
  }
  if (best < 0)
    throw Error(ErrorClass::unsupported, file.string() + ": no flat (non-deep) part of the OpenEXR file holds a rendering",
                "deep images are not read; flatten the rendering first");
  return best;
}

Rendering read(const std::filesystem::path& file) {
  Imf::MultiPartInputFile mp(file.c_str(), exr_threads());
  const int part = choose_part(mp, file);
  const Imf::Header& header = mp.header(part);
  const Layout layout = classify(header, file);
  for (const auto& name : layout.channels) {
    const Imf::Channel* ch = header.channels().findChannel(name);
    if (ch->xSampling != 1 || ch->ySampling != 1)
      throw Error(ErrorClass::unsupported, file.string() + ": channel " + name + " is subsampled",
                  "store every channel at full resolution");
  }
  const Imath::Box2i dw = header.dataWindow();
  const Imath::Box2i disp = header.displayWindow();
  if (dw.min.x < disp.min.x || dw.min.y < disp.min.y || dw.max.x > disp.max.x || dw.max.y > disp.max.y)
    throw Error(ErrorClass::unsupported, file.string() + ": data window extends beyond the display window (overscan)",
                "crop the rendering to its display window (oiiotool FILE --crop full -o OUT)");

  Rendering r;
  r.encoding = layout.encoding;
  r.reflective = layout.reflective;
  r.wavelengths_nm = layout.wavelengths_nm;
  const long long width = static_cast<long long>(disp.max.x) - disp.min.x + 1;
  const long long height = static_cast<long long>(disp.max.y) - disp.min.y + 1;
  const long long channels = static_cast<long long>(layout.channels.size());
  check_dimensions(file, width, height, channels);
  r.width = static_cast<int>(width);
  r.height = static_cast<int>(height);
  // Pixels of the display window outside the data window are zero (OpenEXR's convention for what was not stored).
  r.pixels.assign(static_cast<std::size_t>(width * height * channels), 0.0f);

  const std::size_t xs = sizeof(float) * static_cast<std::size_t>(channels);
  const std::size_t ys = xs * static_cast<std::size_t>(width);
  // OpenEXR addresses slices by absolute pixel coordinates: base + x·xs + y·ys must land on pixel (x − disp.min).
  char* base = reinterpret_cast<char*>(r.pixels.data()) - static_cast<std::ptrdiff_t>(disp.min.x) * static_cast<std::ptrdiff_t>(xs) -
               static_cast<std::ptrdiff_t>(disp.min.y) * static_cast<std::ptrdiff_t>(ys);
  Imf::InputPart in(mp, part);
  if (!read_flat_float_scanlines(in, header, layout.channels, base, xs, ys, file)) {
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < layout.channels.size(); ++c)
      fb.insert(layout.channels[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  }

  switch (r.encoding) {
    case Encoding::spectral:
      r.source_format = "openexr-spectral";
      if (const auto* u = header.findTypedAttribute<Imf::StringAttribute>(r.reflective ? "reflectiveUnits" : "emissiveUnits"))
        r.units = u->value();
      break;
    case Encoding::xyz:
      r.source_format = "openexr-xyz";
      break;
    case Encoding::rgb:
      r.source_format = "openexr-rgb";
      r.chromaticities_from_file = Imf::hasChromaticities(header);
      if (r.chromaticities_from_file) {
        const Imf::Chromaticities& c = Imf::chromaticities(header);
        r.chromaticities = {{{c.red.x, c.red.y}, {c.green.x, c.green.y}, {c.blue.x, c.blue.y}, {c.white.x, c.white.y}}};
      } else {
        r.chromaticities = rec709_chromaticities();
      }
      break;
  }
  if (r.encoding != Encoding::spectral && Imf::hasWhiteLuminance(header)) {
    const double wl = Imf::whiteLuminance(header);
    if (!(wl > 0) || !std::isfinite(wl))
      bad_data(file, "whiteLuminance " + std::to_string(wl) + " is not a positive luminance");
    r.white_luminance_cd_m2 = wl;
    r.units = "cd/m^2 (whiteLuminance)";
  }
  check_values(r, file, layout.channels);
  return r;
}

}  // namespace

Rendering read_openexr(const std::filesystem::path& file) {
  try {
    return read(file);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(ErrorClass::io_error, file.string() + ": not enough memory for the image");
  } catch (const std::exception& e) {
    // OpenEXR reports truncation, corrupt chunks and bad headers as Iex exceptions.
    bad_data(file, std::string("OpenEXR cannot read it: ") + e.what(), "the file is truncated or corrupt; write it again");
  }
}

}  // namespace colorlab::verify::detail
