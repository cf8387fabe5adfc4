// sensor_params.h — the sensor model of a parameter set, in the precision of
// the update (the per-cell math in egrid_math.h knows no MapperParams).
#ifndef VASCO_GPU_INTERNAL_SENSOR_PARAMS_H
#define VASCO_GPU_INTERNAL_SENSOR_PARAMS_H

#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/params.h"

namespace vasco {

template <class Real = double>
egrid::SensorModel<Real> sensor_model_of(const MapperParams &p) {
  return {static_cast<Real>(p.p_prior), static_cast<Real>(p.p_occ), static_cast<Real>(p.p_emp),
          static_cast<Real>(p.range_sure), static_cast<Real>(p.range_max)};
}

}  // namespace vasco

#endif  // VASCO_GPU_INTERNAL_SENSOR_PARAMS_H
