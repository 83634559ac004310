#include "synthetic_chart.hpp"

#include "colorlab/analysis/colorimetry.hpp"
#include "colorlab/analysis/standard_data.hpp"

namespace colorlab::bench {

namespace ca = analysis;

ca::SpectralSet camera_curves(const ca::SpectralSet& collection, const std::string& camera) {
  std::vector<std::size_t> rows;
  for (const char* c : {"_R", "_G", "_B"}) rows.push_back(collection.require(camera + c));
  ca::SpectralSet s = collection.select(rows);
  s.names = {"R", "G", "B"};
  return s;
}

ca::ChartData render_chart(const ca::SpectralSet& refl, const ca::SpectralSet& lamp, const ca::SpectralSet& curves) {
  const auto grid = ca::uniform_grid(curves.wavelengths.front(), curves.wavelengths.back(), 1.0);
  // Reflectances are smooth (Sprague, CIE 167); lamps may have lines and camera curves steep edges: linear for both,
  // so neither invents overshoot. Fluorescent lamps come at 5 nm from colord, so their lines survive.
  const ca::SpectralSet r = ca::resample(refl, grid,
                                         ca::sprague_applicable(refl.wavelengths) ? ca::Interpolation::sprague
                                                                                  : ca::Interpolation::cubic_spline);
  const ca::SpectralSet l = ca::resample(lamp, grid, ca::Interpolation::linear);
  const ca::SpectralSet s = ca::resample(curves, grid, ca::Interpolation::linear);
  const Eigen::RowVectorXd e = l.values.row(0);
  const Eigen::MatrixXd raw = (r.values.array().rowwise() * e.array()).matrix() * s.values.transpose();
  const Eigen::RowVectorXd white = e * s.values.transpose();

  ca::ChartData c;
  c.ids = refl.names;
  c.white = ca::kIccD50White;
  c.rgb = raw.array().rowwise() / white.array();
  const ca::ReflectanceIntegrator integ(lamp, ca::load_observer(ca::Observer::cie1931_2deg), refl.wavelengths);
  const auto xyz = integ.xyz(refl);
  c.xyz.resize(static_cast<Eigen::Index>(xyz.size()), 3);
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    const ca::Xyz a = ca::bradford_adapt(xyz[i], integ.white(), ca::kIccD50White);
    c.xyz.row(static_cast<Eigen::Index>(i)) << a.X, a.Y, a.Z;
  }
  c.lab = ca::xyz_rows_to_lab(c.xyz, c.white);
  return c;
}

}  // namespace colorlab::bench
