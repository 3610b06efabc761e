// gravcal/workflows/discovery_config.h: the discovery part of a Config
// (config.h): what `gravcal discover` reads beyond the calibration part
// (section "discovery", the discovery_* keys).
#ifndef GRAVCAL_WORKFLOWS_DISCOVERY_CONFIG_H_
#define GRAVCAL_WORKFLOWS_DISCOVERY_CONFIG_H_

#include "gravcal/workflows/discovery.h"

namespace gravcal {

struct DiscoveryConfig {
  DiscoveryOptions discovery;
};

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_DISCOVERY_CONFIG_H_
