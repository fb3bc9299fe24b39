#pragma once
// A row of the store's tables read into its record, once for both engines:
// `Row` is an engine's row (SQLite's statement, a PostgreSQL result's row)
// with text(column), integer(column), real(column), isNull(column) and
// columns(). The columns in the order of jobColumns(), kHostColumns and
// kDeviceColumns.

#include "daemon/service/JobStore.h"

namespace rotafab::service {

constexpr const char* kHostColumns = "name, address, started, seen, lease_until, gone";
constexpr const char* kRequestColumns = "id, job, action, arguments, who, at";
constexpr const char* kDeviceColumns = "name, host, machine, material, uri, auto_start, state, message, job";

template <typename Row>
JobRecord jobOf(const Row& row) {
  JobRecord job;
  job.id = row.integer(0);
  job.state = stateNamed(row.text(1)).value_or(JobState::Failed);
  job.kind = row.text(2) == "planned" ? JobKind::Planned : JobKind::Mesh;
  job.source = row.text(3);
  job.owner = row.text(4);
  job.device = row.text(5);
  job.priority = static_cast<int>(row.integer(6));
  job.position = row.real(7);
  job.options = row.text(8);
  job.spool = row.text(9);
  job.submitted = row.real(10);
  job.updated = row.real(11);
  job.sheets = static_cast<int>(row.integer(12));
  job.summary = row.text(13);
  job.sheet = static_cast<int>(row.integer(14));
  job.stroke = row.integer(15);
  job.strokes = row.integer(16);
  job.message = row.text(17);
  if (row.columns() > 18) {  // (schema version 5 on)
    job.host = row.text(18);
    job.anyDevice = row.integer(19) != 0;
  }
  return job;
}

template <typename Row>
HostRecord hostOf(const Row& row) {
  HostRecord host;
  host.name = row.text(0);
  host.address = row.text(1);
  host.started = row.real(2);
  host.seen = row.real(3);
  host.leaseUntil = row.real(4);
  host.gone = row.integer(5) != 0;
  return host;
}

template <typename Row>
DeviceRecord deviceOf(const Row& row) {
  DeviceRecord device;
  device.name = row.text(0);
  device.host = row.text(1);
  device.machine = row.text(2);
  device.material = row.text(3);
  device.uri = row.text(4);
  device.autoStart = row.integer(5) != 0;
  device.state = row.text(6);
  device.message = row.text(7);
  if (!row.isNull(8)) device.job = row.integer(8);
  return device;
}

template <typename Row>
ActionRequest requestOf(const Row& row) {
  return {row.integer(0), row.integer(1), row.text(2), row.text(3), row.text(4), row.real(5)};
}

}  // namespace rotafab::service
