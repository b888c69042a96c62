#pragma once
// The database build on MPI (shapedb::io_mpi, built where MPI is found: SHAPEDB_WITH_MPI): the same
// build as buildDatabase, its entries computed by the other ranks of MPI_COMM_WORLD, on one machine or
// many (`mpirun -np N shapedb build DB --mpi`, or Slurm's `srun`).

#include <filesystem>

#include <shapedb/core/result.h>
#include <shapedb/io/build.h>

namespace shapedb::io {

/// MPI for the life of the object: initialized (threads funnelled through the main one) unless it already
/// was, finalized at the end if it was initialized here.
class MpiEnvironment {
 public:
  MpiEnvironment();
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;
  int rank() const { return mRank; }
  int size() const { return mSize; }

 private:
  bool mInitializedHere = false;
  int mRank = 0, mSize = 1;
};

/// buildDatabase over the ranks of MPI_COMM_WORLD; every rank calls it with the same arguments.
/// Rank 0 owns the file (created, or resumed with options.resume) and the catalog: it hands entries out
/// one at a time to whichever rank is free (entries differ in cost tenfold), receives each computed entry
/// and commits them in batches of options.batchSize, as buildDatabase does; the other ranks compute
/// (options.threads each, 0: all cores). The file is the one buildDatabase would write with the same
/// options: the same entries, ids and bytes. A run with one rank computes on rank 0 itself.
/// A rank that dies ends the job (MPI's default handler); what rank 0 had committed stays, and a build
/// with options.resume, on MPI or not, finishes it. Rank 0 returns buildDatabase's report and errors; the
/// others report the entries they computed (built, failed, seconds), or kCancelled when rank 0 could not
/// start (its error is rank 0's to tell).
Result<BuildReport> buildDatabaseMpi(const std::filesystem::path& path, const BuildOptions& options);

}  // namespace shapedb::io
