#include "gravcal/methods/session.h"

#include "methods/static_positions.h"

namespace gravcal {

bool DetectSessionPoses(const StaticDetectorOptions& detector, Session* session) {
  if (!session->detected) {
    session->detection = StaticDetection();
    session->detection_ok = internal::DetectLog(session->log, detector, &session->detection);
    session->detected = true;
  }
  return session->detection_ok;
}

}  // namespace gravcal
