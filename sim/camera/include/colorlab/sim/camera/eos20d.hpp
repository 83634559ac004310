#pragma once
// The simulated Canon EOS 20D's settings as its firmware offers them (ISO 100–1600, shutter 1/8000–30 s
// in third stops with the firmware's labels, a 2.8–22 zoom): one table for every simulated body,
// the in-process one (drivers/camera SimulatedCamera) and colorlab-sim's tethered one (sim/dslr).
namespace colorlab::sim::camera::eos20d {

inline constexpr const char* kShutterLabels[] = {
    "1/8000", "1/6400", "1/5000", "1/4000", "1/3200", "1/2500", "1/2000", "1/1600", "1/1250", "1/1000", "1/800",
    "1/640", "1/500", "1/400", "1/320", "1/250", "1/200", "1/160", "1/125", "1/100", "1/80", "1/60",
    "1/50", "1/40", "1/30", "1/25", "1/20", "1/15", "1/13", "1/10", "1/8", "1/6", "1/5",
    "1/4", "0.3", "0.4", "0.5", "0.6", "0.8", "1", "1.3", "1.6", "2", "2.5",
    "3.2", "4", "5", "6", "8", "10", "13", "15", "20", "25", "30"};
inline constexpr int kIsos[] = {100, 200, 400, 800, 1600};
inline constexpr double kApertures[] = {2.8, 3.2, 3.5, 4, 4.5, 5, 5.6, 6.3, 7.1, 8, 9, 10, 11, 13, 14, 16, 18, 20, 22};

}  // namespace colorlab::sim::camera::eos20d
