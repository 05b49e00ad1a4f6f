// Sweeps through the real seepd over gRPC: a product and a zipped sweep run to completion with
// every job bit-identical to the same scene submitted on its own (built here by hand, not by the
// sweep code), refusals that name the field and store nothing, and a sweep cancelled, resumed and
// deleted as a whole.
#include <sqlite3.h>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

// A steady 12 x 8 lattice: k = a0^3 / (24 R) exactly (docs/physics.md §1.3), in well under a
// second.
v1::Scene QuickScene() {
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "sweep-quick"
        packing { lattice { kind: LATTICE_KIND_SQUARE columns: 12 rows: 8 radius_m: 1e-3 } }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
        aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
        boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 outlet_pressure_pa: 0 }
        solver { kind: SOLVER_KIND_STEADY }
      )pb",
      &scene));
  return scene;
}

v1::Sweep SweepOf(const v1::Scene& base, const std::string& text) {
  v1::Sweep sweep;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &sweep)) << text;
  *sweep.mutable_scene() = base;
  return sweep;
}

class SweepService : public GrpcSeepdTest {
 protected:
  SweepService() : GrpcSeepdTest("e2e-sweep") {}

  grpc::Status SubmitSweep(const v1::Sweep& sweep, v1::SubmitSweepResponse* response) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::SubmitSweepRequest request;
    *request.mutable_sweep() = sweep;
    return stub_->SubmitSweep(&ctx, request, response);
  }
  v1::SweepStatus GetSweep(const std::string& id, grpc::Status* status_out = nullptr) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::GetSweepRequest request;
    request.set_id(id);
    v1::GetSweepResponse response;
    const grpc::Status status = stub_->GetSweep(&ctx, request, &response);
    if (status_out != nullptr) {
      *status_out = status;
    } else {
      EXPECT_TRUE(status.ok()) << status.error_message();
    }
    return response.sweep();
  }
  v1::SweepStatus WaitSweepFinished(const std::string& id) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (;;) {
      v1::SweepStatus sweep = GetSweep(id);
      const bool done = sweep.counts().queued() == 0 && sweep.counts().running() == 0;
      if (done || std::chrono::steady_clock::now() > deadline) return sweep;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  // Submits the scene as a single job and expects its final state and metrics to equal the sweep
  // job's exactly.
  void ExpectSameAsSingleJob(const v1::Scene& scene, const v1::Job& swept) {
    const v1::Job single = WaitTerminal(Submit(scene));
    ASSERT_EQ(single.state(), v1::JOB_STATE_SUCCEEDED) << single.DebugString();
    ASSERT_EQ(swept.state(), v1::JOB_STATE_SUCCEEDED) << swept.DebugString();
    EXPECT_EQ(swept.result().state_sha256(), single.result().state_sha256()) << swept.name();
    ASSERT_EQ(swept.result().metrics().size(), single.result().metrics().size());
    for (const auto& [name, value] : single.result().metrics()) {
      EXPECT_EQ(swept.result().metrics().at(name), value) << swept.name() << " " << name;
    }
  }
  // The rows of a table in seepd's database (seepd stopped).
  std::int64_t RowCount(const std::string& data, const std::string& table) {
    sqlite3* db = nullptr;
    EXPECT_EQ(
        sqlite3_open_v2((dir_ / data / "seep.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr),
        SQLITE_OK);
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, ("SELECT COUNT(*) FROM " + table).c_str(), -1, &stmt, nullptr),
              SQLITE_OK);
    EXPECT_EQ(sqlite3_step(stmt), SQLITE_ROW);
    const std::int64_t n = sqlite3_column_int64(stmt, 0);
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    return n;
  }
};

TEST_F(SweepService, ProductOfTwoByThreeMatchesSingleJobsExactly) {
  Start("data", {"--workers", "2"});
  const v1::Sweep sweep = SweepOf(QuickScene(), R"pb(
    name: "product"
    combine: SWEEP_COMBINE_PRODUCT
    axes {
      path: "boundary.inlet_pressure_pa"
      numbers: [ 1e5, 3e5 ]
    }
    axes {
      path: "aperture.residual_aperture_m"
      numbers: [ 1e-5, 2e-5, 4e-5 ]
    }
  )pb");
  v1::SubmitSweepResponse submitted;
  const grpc::Status status = SubmitSweep(sweep, &submitted);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(submitted.created());
  EXPECT_EQ(submitted.sweep().id().rfind("s-", 0), 0u);
  ASSERT_EQ(submitted.sweep().jobs_size(), 6);
  const v1::SweepStatus done = WaitSweepFinished(submitted.sweep().id());
  ASSERT_EQ(done.counts().succeeded(), 6u) << done.DebugString();
  EXPECT_EQ(done.fraction_done(), 1.0);
  ASSERT_EQ(done.parameters_size(), 2);
  EXPECT_EQ(done.parameters(0), "boundary.inlet_pressure_pa");
  const double pressures[] = {1e5, 3e5};
  const double apertures[] = {1e-5, 2e-5, 4e-5};
  for (int p = 0; p < 6; ++p) {
    const v1::SweepJob& member = done.jobs(p);
    ASSERT_EQ(member.position(), static_cast<std::uint32_t>(p));
    // The last axis varies fastest.
    const double pressure = pressures[p / 3];
    const double aperture = apertures[p % 3];
    EXPECT_EQ(member.settings(0).number(), pressure);
    EXPECT_EQ(member.settings(1).number(), aperture);
    EXPECT_EQ(member.job().name(), "product/" + std::to_string(p));
    EXPECT_EQ(member.job().labels().at("sweep"), done.id());
    // k = a0^3 / (24 R) whatever the pressure; the inflow scales with it.
    const double k = aperture * aperture * aperture / (24.0 * 1e-3);
    EXPECT_NEAR(member.job().result().metrics().at("permeability_m2"), k, 1e-9 * k);
    v1::Scene by_hand = QuickScene();
    by_hand.mutable_boundary()->set_inlet_pressure_pa(pressure);
    by_hand.mutable_aperture()->set_residual_aperture_m(aperture);
    ExpectSameAsSingleJob(by_hand, Get(member.job().id()));
  }
}

TEST_F(SweepService, ZippedTransientSweepMatchesSingleJobsExactly) {
  Start("data", {"--workers", "2", "--checkpoint-every-steps", "20"});
  // Explicit steps with checkpoints: each job runs as any job does.
  v1::Scene base = QuickScene();
  base.mutable_solver()->set_kind(v1::SOLVER_KIND_EXPLICIT);
  base.mutable_solver()->set_storage(v1::STORAGE_VOLUME_PORE);
  base.mutable_solver()->set_dt_factor(0.9);
  base.mutable_solver()->set_end_time_s(2e-4);
  const v1::Sweep sweep = SweepOf(base, R"pb(
    combine: SWEEP_COMBINE_ZIP
    axes {
      path: "boundary.inlet_pressure_pa"
      numbers: [ 1e5, 2e5, 5e5 ]
    }
    axes {
      path: "solver.dt_factor"
      numbers: [ 0.9, 0.5, 0.25 ]
    }
    axes {
      path: "solver.storage"
      texts: [ "STORAGE_VOLUME_PORE", "STORAGE_VOLUME_APPARENT", "STORAGE_VOLUME_PORE" ]
    }
  )pb");
  v1::SubmitSweepResponse submitted;
  const grpc::Status status = SubmitSweep(sweep, &submitted);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(submitted.sweep().jobs_size(), 3);
  EXPECT_EQ(submitted.sweep().name(), "sweep-quick");  // the base's name
  const v1::SweepStatus done = WaitSweepFinished(submitted.sweep().id());
  ASSERT_EQ(done.counts().succeeded(), 3u) << done.DebugString();
  const double pressures[] = {1e5, 2e5, 5e5};
  const double factors[] = {0.9, 0.5, 0.25};
  const v1::StorageVolume storages[] = {v1::STORAGE_VOLUME_PORE, v1::STORAGE_VOLUME_APPARENT,
                                        v1::STORAGE_VOLUME_PORE};
  for (int p = 0; p < 3; ++p) {
    EXPECT_EQ(done.jobs(p).settings(2).text(), v1::StorageVolume_Name(storages[p]));
    v1::Scene by_hand = base;
    by_hand.mutable_boundary()->set_inlet_pressure_pa(pressures[p]);
    by_hand.mutable_solver()->set_dt_factor(factors[p]);
    by_hand.mutable_solver()->set_storage(storages[p]);
    const v1::Job swept = Get(done.jobs(p).job().id());
    EXPECT_GT(swept.progress().step(), 10u);
    ExpectSameAsSingleJob(by_hand, swept);
  }
}

TEST_F(SweepService, CalibrationReplicatesMatchSingleCalibrationsAndRequestIdsRepeat) {
  Start("data", {"--workers", "2"});
  v1::Sweep sweep;
  ASSERT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "calibrations"
        calibration {
          scene {
            packing {
              random {
                seed: 7
                width_m: 0.04
                height_m: 0.02
                min_radius_m: 0.8e-3
                max_radius_m: 1.0e-3
                particle_count: 300
                target_porosity: 0.22
              }
              contact_gap_m: 2e-5
            }
            fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
            aperture { reference_force_n: 10 gap_multiplier: 0.5 }
            boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 outlet_pressure_pa: 0 }
          }
          stress { uniform_normal_force_n: 5 }
          target_permeabilities_m2: [ 1e-13 ]
        }
        replicates { seed_path: "scene.packing.random.seed" count: 2 }
      )pb",
      &sweep));
  grpc::ClientContext ctx;
  v1::SubmitSweepRequest request;
  *request.mutable_sweep() = sweep;
  request.set_request_id("calibrations-1");
  v1::SubmitSweepResponse submitted;
  const grpc::Status status = stub_->SubmitSweep(&ctx, request, &submitted);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(submitted.sweep().jobs_size(), 2);
  EXPECT_EQ(submitted.sweep().parameters(0), "scene.packing.random.seed");
  const v1::SweepStatus done = WaitSweepFinished(submitted.sweep().id());
  ASSERT_EQ(done.counts().succeeded(), 2u) << done.DebugString();

  // The same request id: the same sweep, nothing new; with another sweep: ALREADY_EXISTS.
  {
    grpc::ClientContext again;
    v1::SubmitSweepResponse repeated;
    ASSERT_TRUE(stub_->SubmitSweep(&again, request, &repeated).ok());
    EXPECT_FALSE(repeated.created());
    EXPECT_EQ(repeated.sweep().id(), done.id());
    EXPECT_EQ(repeated.sweep().jobs(1).job().id(), done.jobs(1).job().id());
    grpc::ClientContext other;
    request.mutable_sweep()->mutable_replicates()->set_count(3);
    EXPECT_EQ(stub_->SubmitSweep(&other, request, &repeated).error_code(),
              grpc::StatusCode::ALREADY_EXISTS);
  }

  for (int p = 0; p < 2; ++p) {
    EXPECT_EQ(done.jobs(p).settings(0).number(), 7.0 + p);  // from the base's own seed on
    const v1::Job swept = Get(done.jobs(p).job().id());
    EXPECT_EQ(swept.kind(), v1::JOB_KIND_CALIBRATION);
    v1::Calibration by_hand = sweep.calibration();
    by_hand.mutable_scene()->mutable_packing()->mutable_random()->set_seed(7 + p);
    grpc::ClientContext single_ctx;
    v1::SubmitJobRequest single_request;
    *single_request.mutable_calibration() = by_hand;
    v1::SubmitJobResponse single;
    ASSERT_TRUE(stub_->SubmitJob(&single_ctx, single_request, &single).ok());
    const v1::Job alone = WaitTerminal(single.job().id());
    ASSERT_EQ(alone.state(), v1::JOB_STATE_SUCCEEDED) << alone.DebugString();
    ASSERT_GT(alone.result().metrics().size(), 0u);
    ASSERT_EQ(swept.result().metrics().size(), alone.result().metrics().size());
    for (const auto& [name, value] : alone.result().metrics()) {
      EXPECT_EQ(swept.result().metrics().at(name), value) << name;
    }
  }
  // Two seeds, two packings: the calibrated a0 differs between the replicates.
  EXPECT_NE(Get(done.jobs(0).job().id()).result().metrics().at("residual_aperture_m[0]"),
            Get(done.jobs(1).job().id()).result().metrics().at("residual_aperture_m[0]"));
}

TEST_F(SweepService, RefusalsNameTheFieldAndStoreNothing) {
  Start("data", {"--workers", "1"});
  const v1::Scene base = QuickScene();
  const auto refused = [&](const std::string& text) {
    v1::SubmitSweepResponse response;
    const grpc::Status status = SubmitSweep(SweepOf(base, text), &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << text;
    return status.error_message();
  };
  // A bad field path.
  EXPECT_EQ(refused(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "boundary.inlet_pressure_pa"
                           numbers: [ 1e5 ]
                         }
                         axes {
                           path: "boundary.inlet_presure_pa"
                           numbers: [ 1e5 ]
                         })pb")
                .rfind("sweep.axes[1].path: 'boundary.inlet_presure_pa': seep.v1.Boundary has "
                       "no field 'inlet_presure_pa'",
                       0),
            0u);
  // A value of the wrong type.
  EXPECT_EQ(refused(R"pb(combine: SWEEP_COMBINE_PRODUCT
                         axes {
                           path: "packing.lattice.columns"
                           numbers: [ 12, 12.5 ]
                         })pb"),
            "sweep.axes[0].numbers[1]: packing.lattice.columns = 12.5: is not an integer (got "
            "12.5)");
  // A point whose scene fails validation: the second viscosity, after the first point passed.
  const std::string invalid = refused(R"pb(combine: SWEEP_COMBINE_PRODUCT
                                           axes {
                                             path: "boundary.inlet_pressure_pa"
                                             numbers: [ 1e5, 2e5 ]
                                           }
                                           axes {
                                             path: "fluid.viscosity_pa_s"
                                             numbers: [ 1e-3, -1 ]
                                           })pb");
  EXPECT_EQ(invalid.rfind("sweep.axes[1].numbers[1]: fluid.viscosity_pa_s = -1 makes an invalid "
                          "scene: scene.fluid.viscosity_pa_s: must be",
                          0),
            0u)
      << invalid;
  // An invalid point whose failing field is not swept: the base and the point are named.
  const std::string unswept = refused(R"pb(combine: SWEEP_COMBINE_PRODUCT
                                           axes {
                                             path: "solver.kind"
                                             texts: [ "SOLVER_KIND_STEADY", "SOLVER_KIND_EXPLICIT" ]
                                           })pb");
  EXPECT_EQ(unswept.rfind("sweep.scene: job 1 of the sweep (solver.kind = SOLVER_KIND_EXPLICIT) "
                          "is an invalid scene: scene.solver.",
                          0),
            0u)
      << unswept;
  // The "sweep" label is the sweep's own.
  {
    grpc::ClientContext ctx;
    v1::SubmitSweepRequest request;
    *request.mutable_sweep() = SweepOf(base, R"pb(combine: SWEEP_COMBINE_PRODUCT
                                                  axes {
                                                    path: "boundary.inlet_pressure_pa"
                                                    numbers: [ 1e5 ]
                                                  })pb");
    (*request.mutable_labels())["sweep"] = "mine";
    v1::SubmitSweepResponse response;
    const grpc::Status status = stub_->SubmitSweep(&ctx, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message().rfind("labels[\"sweep\"]: is set by the sweep itself", 0), 0u)
        << status.error_message();
  }
  grpc::Status unknown;
  GetSweep("s-0000000000000000", &unknown);
  EXPECT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND);
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);
  EXPECT_EQ(RowCount("data", "jobs"), 0);
  EXPECT_EQ(RowCount("data", "sweeps"), 0);
  EXPECT_EQ(RowCount("data", "sweep_jobs"), 0);
}

TEST_F(SweepService, CancelResumeAndDeleteActOnTheWholeSweep) {
  // One worker: one job runs (without end in the test's time), the others wait in the queue.
  Start("data", {"--workers", "1", "--checkpoint-every-steps", "100"});
  // 1 s of simulated time: minutes of steps, with progress from the first few hundred on.
  const v1::Scene endless = LatticeScene("endless", 1.0);
  const v1::Sweep sweep = SweepOf(endless, R"pb(
    combine: SWEEP_COMBINE_PRODUCT
    axes {
      path: "boundary.inlet_pressure_pa"
      numbers: [ 1e5, 2e5, 3e5 ]
    }
  )pb");
  v1::SubmitSweepResponse submitted;
  ASSERT_TRUE(SubmitSweep(sweep, &submitted).ok());
  const std::string id = submitted.sweep().id();
  std::vector<std::string> job_ids;
  for (const auto& member : submitted.sweep().jobs()) job_ids.push_back(member.job().id());
  ASSERT_EQ(job_ids.size(), 3u);
  const v1::Job running = WaitFor(job_ids[0], [](const v1::Job& j) {
    return j.state() == v1::JOB_STATE_RUNNING && j.progress().step() > 0;
  });
  ASSERT_EQ(running.state(), v1::JOB_STATE_RUNNING);

  const auto call = [&](auto method, const auto& request, auto* response) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    return ((*stub_).*method)(&ctx, request, response);
  };
  v1::DeleteSweepRequest delete_request;
  delete_request.set_id(id);
  v1::DeleteSweepResponse deleted;
  // Not while a job runs: refused naming it, and nothing goes.
  grpc::Status status = call(&v1::SeepService::Stub::DeleteSweep, delete_request, &deleted);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_NE(status.error_message().find(job_ids[0] + " is RUNNING"), std::string::npos)
      << status.error_message();
  EXPECT_EQ(GetSweep(id).jobs_size(), 3);

  v1::CancelSweepRequest cancel_request;
  cancel_request.set_id(id);
  v1::CancelSweepResponse cancelled;
  status = call(&v1::SeepService::Stub::CancelSweep, cancel_request, &cancelled);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(cancelled.jobs_cancelled(), 2u);
  EXPECT_EQ(cancelled.cancels_requested(), 1u);
  v1::SweepStatus after = WaitSweepFinished(id);
  EXPECT_EQ(after.counts().cancelled(), 3u) << after.DebugString();
  // Nothing left to cancel.
  status = call(&v1::SeepService::Stub::CancelSweep, cancel_request, &cancelled);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  // Resume queues all three again as new attempts; then cancel them once more.
  v1::ResumeSweepRequest resume_request;
  resume_request.set_id(id);
  v1::ResumeSweepResponse resumed;
  status = call(&v1::SeepService::Stub::ResumeSweep, resume_request, &resumed);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(resumed.jobs_resumed(), 3u);
  for (const auto& member : resumed.sweep().jobs()) EXPECT_EQ(member.job().attempt(), 2u);
  ASSERT_TRUE(call(&v1::SeepService::Stub::CancelSweep, cancel_request, &cancelled).ok());
  after = WaitSweepFinished(id);
  EXPECT_EQ(after.counts().cancelled(), 3u) << after.DebugString();

  status = call(&v1::SeepService::Stub::DeleteSweep, delete_request, &deleted);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(deleted.jobs_deleted(), 3u);
  EXPECT_GE(deleted.checkpoints_deleted(), 1u);  // the first job ran long enough to keep one
  grpc::Status gone;
  GetSweep(id, &gone);
  EXPECT_EQ(gone.error_code(), grpc::StatusCode::NOT_FOUND);
  for (const std::string& job : job_ids) {
    grpc::ClientContext ctx;
    v1::GetJobRequest request;
    request.set_id(job);
    v1::GetJobResponse response;
    EXPECT_EQ(stub_->GetJob(&ctx, request, &response).error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_FALSE(std::filesystem::exists(dir_ / "data" / "checkpoints" / job));
  }
}

}  // namespace
}  // namespace seep::testing
