#include "navbus/records/message_fields.hpp"

namespace navbus::records {

const char* enumName(navbus::FilterMode v) {
  switch (v) {
    case navbus::MODE_INITIALIZING:
      return "INITIALIZING";
    case navbus::MODE_INERTIAL_ONLY:
      return "INERTIAL_ONLY";
    case navbus::MODE_TIGHTLY_COUPLED:
      return "TIGHTLY_COUPLED";
    case navbus::MODE_LOOSELY_COUPLED:
      return "LOOSELY_COUPLED";
    case navbus::MODE_MDF_F1_ZUPT:
      return "MDF_F1_ZUPT";
    case navbus::MODE_MDF_F2_GNSS:
      return "MDF_F2_GNSS";
    case navbus::MODE_MDF_F3_RECOVERY:
      return "MDF_F3_RECOVERY";
    case navbus::MODE_MDF_F4_CIF:
      return "MDF_F4_CIF";
    case navbus::MODE_INERTIAL_LOST:
      return "INERTIAL_LOST";
    case navbus::MODE_AIDED_AXIS_FAILED:
      return "AIDED_AXIS_FAILED";
    case navbus::MODE_ALIGNING:
      return "ALIGNING";
    case navbus::MODE_REINITIALISING:
      return "REINITIALISING";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::IntegrityState v) {
  switch (v) {
    case navbus::INTEGRITY_NOT_MONITORED:
      return "NOT_MONITORED";
    case navbus::INTEGRITY_INITIALIZING:
      return "INITIALIZING";
    case navbus::INTEGRITY_AVAILABLE:
      return "AVAILABLE";
    case navbus::INTEGRITY_UNAVAILABLE:
      return "UNAVAILABLE";
  }
  return "UNKNOWN";
}

const char* enumName(navbus::SolutionOutput v) {
  switch (v) {
    case navbus::OUTPUT_DETERMINISTIC:
      return "DETERMINISTIC";
    case navbus::OUTPUT_LOW_LATENCY:
      return "LOW_LATENCY";
  }
  return "UNKNOWN";
}

const char* enumName(navbus::StartSource v) {
  switch (v) {
    case navbus::START_CONFIGURED:
      return "CONFIGURED";
    case navbus::START_STAR_TRACKER:
      return "STAR_TRACKER";
    case navbus::START_GYROCOMPASS:
      return "GYROCOMPASS";
    case navbus::START_GNSS_COURSE:
      return "GNSS_COURSE";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::FusionStructure v) {
  switch (v) {
    case navbus::FUSION_NONE:
      return "NONE";
    case navbus::FUSION_CENTRALIZED:
      return "CENTRALIZED";
    case navbus::FUSION_FEDERATED:
      return "FEDERATED";
    case navbus::FUSION_ADAPTIVE:
      return "ADAPTIVE";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::FaultSource v) {
  switch (v) {
    case navbus::SOURCE_IMU_STREAM:
      return "IMU_STREAM";
    case navbus::SOURCE_IMU_RAW_STREAM:
      return "IMU_RAW_STREAM";
    case navbus::SOURCE_GNSS_OBS_STREAM:
      return "GNSS_OBS_STREAM";
    case navbus::SOURCE_GNSS_FIX_STREAM:
      return "GNSS_FIX_STREAM";
    case navbus::SOURCE_ST_STREAM:
      return "ST_STREAM";
    case navbus::SOURCE_ACCELEROMETER:
      return "ACCELEROMETER";
    case navbus::SOURCE_GYRO:
      return "GYRO";
    case navbus::SOURCE_SATELLITE:
      return "SATELLITE";
    case navbus::SOURCE_STAR_TRACKER:
      return "STAR_TRACKER";
    case navbus::SOURCE_RECEIVER_CLOCK:
      return "RECEIVER_CLOCK";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::FaultEvent v) {
  switch (v) {
    case navbus::EVENT_STREAM_LOST:
      return "STREAM_LOST";
    case navbus::EVENT_STREAM_RESTORED:
      return "STREAM_RESTORED";
    case navbus::EVENT_FAULT_DETECTED:
      return "FAULT_DETECTED";
    case navbus::EVENT_FAULT_CLEARED:
      return "FAULT_CLEARED";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::FaultShape v) {
  switch (v) {
    case navbus::SHAPE_NONE:
      return "NONE";
    case navbus::SHAPE_STEP:
      return "STEP";
    case navbus::SHAPE_RAMP:
      return "RAMP";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::SatelliteScope v) {
  switch (v) {
    case navbus::SCOPE_ALL:
      return "ALL";
    case navbus::SCOPE_PSEUDORANGE:
      return "PSEUDORANGE";
    case navbus::SCOPE_PSEUDORANGE_RATE:
      return "PSEUDORANGE_RATE";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::CommandKind v) {
  switch (v) {
    case navbus::CMD_EXCLUDE_SATELLITE:
      return "EXCLUDE_SATELLITE";
    case navbus::CMD_READMIT_SATELLITE:
      return "READMIT_SATELLITE";
    case navbus::CMD_COMPENSATE_BIAS:
      return "COMPENSATE_BIAS";
    case navbus::CMD_SELECT_FUSION:
      return "SELECT_FUSION";
    case navbus::CMD_SELECT_MODE:
      return "SELECT_MODE";
    case navbus::CMD_RESET:
      return "RESET";
    case navbus::CMD_EXCLUDE_STREAM:
      return "EXCLUDE_STREAM";
    case navbus::CMD_READMIT_STREAM:
      return "READMIT_STREAM";
    case navbus::CMD_RELEARN_BIAS:
      return "RELEARN_BIAS";
    case navbus::CMD_FAIL_SENSOR_AXIS:
      return "FAIL_SENSOR_AXIS";
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      return "RESTORE_SENSOR_AXIS";
    case navbus::CMD_SUSPECT_SENSOR_AXIS:
      return "SUSPECT_SENSOR_AXIS";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::CommandOutcomeKind v) {
  switch (v) {
    case navbus::OUTCOME_APPLIED:
      return "APPLIED";
    case navbus::OUTCOME_CLAMPED:
      return "CLAMPED";
    case navbus::OUTCOME_REFUSED:
      return "REFUSED";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::ParticipantState v) {
  switch (v) {
    case navbus::STATE_STARTING:
      return "STARTING";
    case navbus::STATE_RUNNING:
      return "RUNNING";
    case navbus::STATE_DEGRADED:
      return "DEGRADED";
    case navbus::STATE_STOPPING:
      return "STOPPING";
    case navbus::STATE_ENDED:
      return "ENDED";
  }
  return "UNKNOWN";
}
const char* enumName(navbus::MeasurementKind v) {
  switch (v) {
    case navbus::MEAS_PSEUDORANGE:
      return "PSEUDORANGE";
    case navbus::MEAS_PSEUDORANGE_RATE:
      return "PSEUDORANGE_RATE";
    case navbus::MEAS_POSITION:
      return "POSITION";
    case navbus::MEAS_VELOCITY:
      return "VELOCITY";
    case navbus::MEAS_ATTITUDE:
      return "ATTITUDE";
    case navbus::MEAS_ZERO_VELOCITY:
      return "ZERO_VELOCITY";
    case navbus::MEAS_NONHOLONOMIC:
      return "NONHOLONOMIC";
  }
  return "UNKNOWN";
}

}  // namespace navbus::records
