// The database subcommands as a user runs them: the real executable, a real file, a real SIGKILL.

#include <algorithm>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/tetrahedralize.h>

#include "cli_test_support.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

/// Every row of the tables that hold the entries, as text (blobs as hex), ordered: what two databases
/// must share to be "the same database". Build times are left out.
std::string dumpEntries(const std::filesystem::path& path) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  std::string out;
  for (const char* sql :
       {"SELECT id, name, family, params, source, nodes, tets FROM entries ORDER BY id",
        "SELECT entry_id, kind, hex(data), checksum FROM descriptors ORDER BY entry_id, kind",
        "SELECT entry_id, part, hex(data), checksum FROM physics ORDER BY entry_id, part",
        "SELECT name, message FROM failures ORDER BY name"}) {
    sqlite3_stmt* stmt = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr), SQLITE_OK);
    while (sqlite3_step(stmt) == SQLITE_ROW) {
      for (int c = 0; c < sqlite3_column_count(stmt); ++c) {
        const auto* text = sqlite3_column_text(stmt, c);
        out += text ? reinterpret_cast<const char*>(text) : "NULL";
        out += '|';
      }
      out += '\n';
    }
    sqlite3_finalize(stmt);
  }
  sqlite3_close(db);
  return out;
}

/// A resumed database must hold exactly what a clean build holds; on a difference, says where (the first
/// row that differs; blobs are hex, so cut short).
void expectSameEntries(const std::filesystem::path& resumed, const std::filesystem::path& clean) {
  const std::string a = dumpEntries(resumed), b = dumpEntries(clean);
  if (a == b) return;
  std::size_t line = 0, at = 0;
  while (at < std::min(a.size(), b.size()) && a[at] == b[at])
    line += a[at++] == '\n' ? 1 : 0;
  const auto lineAt = [](const std::string& s, std::size_t from) {
    const std::size_t begin = s.rfind('\n', from) == std::string::npos ? 0 : s.rfind('\n', from) + 1;
    return s.substr(begin, std::min<std::size_t>(200, s.find('\n', begin) - begin));
  };
  ADD_FAILURE() << "the resumed database differs from the clean one at row " << line
                << ":\n  resumed: " << lineAt(a, at) << "\n  clean:   " << lineAt(b, at);
}

std::size_t committedEntries(const std::filesystem::path& path) {
  auto store = io::Store::open(path);
  if (!store) return 0;
  auto entries = store->entries();
  return entries ? entries->size() : 0;
}

TEST(BuildCli, KilledWithSigkillThenResumedEqualsACleanBuild) {
  test::ScratchDir dir("build-kill");
  const auto killed = dir / "killed.db", clean = dir / "clean.db";
  const std::vector<std::string> args = {"--entries", "24", "--families", "box,cone:2,shard",
                                         "--modes",   "4",  "--threads",  "1",
                                         "--batch",   "2",  "--quiet"};

  // Start a build and kill it for real once a few batches are committed (and the next is in flight).
  std::vector<std::string> argv = {"build", killed.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  test::RunningProcess build(SHAPEDB_CLI, argv);
  ASSERT_TRUE(build.started());
  test::waitUntil([&] { return committedEntries(killed) >= 6; }, 120.0);
  ASSERT_TRUE(build.kill()) << "the build finished before it was killed";
  const std::size_t atKill = committedEntries(killed);
  std::printf("killed with %zu of 24 entries committed\n", atKill);
  ASSERT_GE(atKill, 6u);
  ASSERT_LT(atKill, 24u);

  // Resume with no parameters: the file's own are used.
  test::ProcessResult resumed =
      test::runProcess(SHAPEDB_CLI, {"build", killed.string(), "--resume", "--quiet"});
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  EXPECT_NE(resumed.out.find(std::to_string(atKill) + " already there"), std::string::npos) << resumed.out;

  std::vector<std::string> cleanArgs = {"build", clean.string()};
  cleanArgs.insert(cleanArgs.end(), args.begin(), args.end());
  test::ProcessResult fresh = test::runProcess(SHAPEDB_CLI, cleanArgs);
  ASSERT_EQ(fresh.exitCode, 0) << fresh.err;

  EXPECT_EQ(committedEntries(killed), 24u);
  expectSameEntries(killed, clean);

  // A resume that asks for other parameters is refused, and says why.
  test::ProcessResult conflict =
      test::runProcess(SHAPEDB_CLI, {"build", killed.string(), "--resume", "--modes", "8", "--quiet"});
  EXPECT_EQ(conflict.exitCode, 2);
  EXPECT_NE(conflict.err.find("was built with another modes"), std::string::npos) << conflict.err;
  // The same families weighted otherwise are another catalog.
  conflict = test::runProcess(
      SHAPEDB_CLI, {"build", killed.string(), "--resume", "--families", "box,cone,shard", "--quiet"});
  EXPECT_EQ(conflict.exitCode, 2);
  EXPECT_NE(conflict.err.find("was built with another families"), std::string::npos) << conflict.err;
}

TEST(BuildCli, ShardsBuiltSeparatelyAndMergedEqualASingleBuild) {
  test::ScratchDir dir("build-shards");
  const std::vector<std::string> args = {"--entries", "14", "--families", "box,cone:2,shard",
                                         "--modes",   "4",  "--quiet"};
  const auto build = [&](const std::filesystem::path& file, std::vector<std::string> more) {
    std::vector<std::string> argv = {"build", file.string()};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), more.begin(), more.end());
    const test::ProcessResult r = test::runProcess(SHAPEDB_CLI, argv);
    EXPECT_EQ(r.exitCode, 0) << r.err;
  };
  build(dir / "whole.db", {});
  for (int k = 0; k < 3; ++k)
    build(dir / ("part" + std::to_string(k) + ".db"), {"--shard", std::to_string(k) + "/3"});
  // Each shard holds its interleaved part (14 entries: 5, 5 and 4) and says which it is.
  const nlohmann::json info = nlohmann::json::parse(
      test::runProcess(SHAPEDB_CLI, {"info", (dir / "part2.db").string(), "--json"}).out);
  EXPECT_EQ(info["shard"], "2/3");
  EXPECT_EQ(info["entries"], 4);
  // A shard resumed with another part is refused; with its own, there is nothing left to do.
  test::ProcessResult r =
      test::runProcess(SHAPEDB_CLI, {"build", (dir / "part1.db").string(), "--resume", "--shard", "0/3"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("was built with another shard"), std::string::npos) << r.err;
  r = test::runProcess(SHAPEDB_CLI, {"build", (dir / "part1.db").string(), "--resume", "--quiet"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("0 entries built, 0 failed, 5 already there"), std::string::npos) << r.out;

  // Merged in any order: the single build's database, entry for entry and byte for byte.
  r = test::runProcess(SHAPEDB_CLI, {"merge", (dir / "merged.db").string(), (dir / "part2.db").string(),
                                     (dir / "part0.db").string(), (dir / "part1.db").string(), "--quiet"});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("14 entries and 0 failures from 3 shards"), std::string::npos) << r.out;
  expectSameEntries(dir / "merged.db", dir / "whole.db");
  const nlohmann::json merged = nlohmann::json::parse(
      test::runProcess(SHAPEDB_CLI, {"info", (dir / "merged.db").string(), "--json", "--check"}).out);
  EXPECT_EQ(merged["status"], "complete");
  EXPECT_FALSE(merged.contains("shard"));
  EXPECT_TRUE(merged["check"]["ok"]);

  // What cannot be merged is refused, naming the files, and leaves no output behind.
  build(dir / "other.db", {"--shard", "2/3", "--poisson", "0.25"});
  build(dir / "quarter.db", {"--shard", "3/4"});
  const auto refused = [&](std::vector<std::string> shards, const std::string& why) {
    SCOPED_TRACE(why);
    std::vector<std::string> argv = {"merge", (dir / "refused.db").string()};
    for (const std::string& shard : shards)
      argv.push_back((dir / shard).string());
    const test::ProcessResult m = test::runProcess(SHAPEDB_CLI, argv);
    EXPECT_EQ(m.exitCode, 2);
    EXPECT_NE(m.err.find(why), std::string::npos) << m.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "refused.db"));
  };
  refused({"part0.db", "part1.db"}, "shard(s) 2 of 3 missing");
  refused({"part0.db", "part1.db", "part1.db", "part2.db"}, "are both shard 1/3: they overlap");
  refused({"part0.db", "part1.db", "other.db"}, "other.db: built with other parameters than");
  refused({"part0.db", "part1.db", "part2.db", "quarter.db"}, "is shard 3/4 but");
  refused({"merged.db", "part0.db"}, "part0.db is shard 0/3 but");
  refused({"whole.db", "merged.db"}, "are both shard 0/1: they overlap");
  const test::ProcessResult exists =
      test::runProcess(SHAPEDB_CLI, {"merge", (dir / "merged.db").string(), (dir / "part0.db").string()});
  EXPECT_EQ(exists.exitCode, 1);
  EXPECT_NE(exists.err.find("exists"), std::string::npos) << exists.err;

  // A damaged blob in a shard is found on the way, named, and nothing is written or left behind.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "part2.db").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE physics SET data = X'00' WHERE entry_id = 2 AND part = 2", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  const test::ProcessResult damaged =
      test::runProcess(SHAPEDB_CLI, {"merge", (dir / "refused.db").string(), (dir / "part0.db").string(),
                                     (dir / "part1.db").string(), (dir / "part2.db").string(), "--quiet"});
  EXPECT_EQ(damaged.exitCode, 1);
  EXPECT_NE(damaged.err.find("physics part 2 does not match its checksum"), std::string::npos) << damaged.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "refused.db"));
  for (const char* leftover : {"refused.db.merging", "refused.db.merging-wal", "refused.db.merging-shm"})
    EXPECT_FALSE(std::filesystem::exists(dir / leftover)) << leftover;
}

#ifdef SHAPEDB_MPIEXEC
/// mpirun with as many ranks as asked on any machine (more ranks than cores), as root too (CI's).
test::ProcessResult runMpi(int ranks, const std::vector<std::string>& args) {
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  std::vector<std::string> argv = {"--oversubscribe", "-np", std::to_string(ranks), SHAPEDB_CLI};
  argv.insert(argv.end(), args.begin(), args.end());
  return test::runProcess(SHAPEDB_MPIEXEC, argv);
}

/// The pid of the process whose command line holds `needle` and whose MPI rank is `rank`, or 0.
pid_t findRank(const std::string& needle, int rank) {
  std::error_code ec;  // processes come and go while /proc is read
  for (auto it = std::filesystem::directory_iterator("/proc", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    const std::filesystem::directory_entry& e = *it;
    const std::string pid = e.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = test::readFile(e.path() / "cmdline"),
                environment = test::readFile(e.path() / "environ");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(needle) != std::string::npos && cmdline.find("--mpi") != std::string::npos &&
        environment.find("OMPI_COMM_WORLD_RANK=" + std::to_string(rank) + '\0') != std::string::npos)
      return static_cast<pid_t>(std::stol(pid));
  }
  return 0;
}

TEST(BuildCli, AnMpiBuildOnThreeRanksEqualsASingleBuildAndAKilledRankIsResumed) {
  test::ScratchDir dir("build-mpi");
  const std::vector<std::string> args = {"--entries", "24", "--families", "box,cone:2,shard",
                                         "--modes",   "4",  "--threads",  "1",
                                         "--batch",   "2",  "--quiet"};
  const auto withArgs = [&](std::vector<std::string> head) {
    head.insert(head.end(), args.begin(), args.end());
    return head;
  };
  const test::ProcessResult single =
      test::runProcess(SHAPEDB_CLI, withArgs({"build", (dir / "single.db").string()}));
  ASSERT_EQ(single.exitCode, 0) << single.err;

  // Rank 0 writes, ranks 1 and 2 compute: the same file, entry for entry and byte for byte.
  const test::ProcessResult mpi = runMpi(3, withArgs({"build", (dir / "mpi.db").string(), "--mpi"}));
  ASSERT_EQ(mpi.exitCode, 0) << mpi.err;
  EXPECT_NE(mpi.out.find("on 3 MPI ranks (rank 0 writing, 2 computing)"), std::string::npos) << mpi.out;
  EXPECT_NE(mpi.out.find("24 entries built"), std::string::npos) << mpi.out;
  expectSameEntries(dir / "mpi.db", dir / "single.db");

  // A computing rank killed for real once a batch is in: the job ends, what was committed stays, and a
  // resumed build (on MPI again) finishes the same file. The other ranks go on until mpirun ends them
  // (here a dozen more entries were committed meanwhile), so rank 1 is found before the batch is waited for,
  // and a job that finished first on a loaded machine is run again rather than taken for a kill.
  const std::filesystem::path killed = dir / "killed.db";
  std::vector<std::string> argv = {"--oversubscribe", "-np",           "3",    SHAPEDB_CLI,
                                   "build",           killed.string(), "--mpi"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::size_t atKill = 24;
  for (int attempt = 0; attempt < 3 && atKill == 24; ++attempt) {
    for (const char* suffix : {"", "-wal", "-shm"})
      std::filesystem::remove(killed.string() + suffix);
    test::RunningProcess job(SHAPEDB_MPIEXEC, argv);
    ASSERT_TRUE(job.started());
    pid_t worker = 0;
    ASSERT_TRUE(test::waitUntil(
        [&] {
          if (worker == 0) worker = findRank(killed.string(), 1);
          return worker > 0 && committedEntries(killed) >= 2;
        },
        120.0))
        << "rank 1 not found, or no batch committed";
    ASSERT_EQ(::kill(worker, SIGKILL), 0);
    ASSERT_TRUE(test::waitUntil([&] { return findRank(killed.string(), 0) == 0; }, 60.0))
        << "the job went on without rank 1";
    job.kill();  // reaps mpirun, whatever it did
    atKill = committedEntries(killed);
    std::printf("rank 1 killed with %zu of 24 entries committed\n", atKill);
  }
  ASSERT_LT(atKill, 24u) << "the build finished before its rank was killed, three times";
  const test::ProcessResult resumed = runMpi(3, {"build", killed.string(), "--mpi", "--resume", "--quiet"});
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  EXPECT_NE(resumed.out.find(std::to_string(atKill) + " already there"), std::string::npos) << resumed.out;
  expectSameEntries(killed, dir / "single.db");

  // Rank 0's refusal ends every rank, with its message.
  const test::ProcessResult exists = runMpi(3, withArgs({"build", (dir / "mpi.db").string(), "--mpi"}));
  EXPECT_NE(exists.exitCode, 0);
  EXPECT_NE(exists.err.find("already exists"), std::string::npos) << exists.err;
}
#endif

TEST(BuildCli, AFullDiskFailsClearlyKeepsWhatWasCommittedAndTheBuildResumes) {
  test::ScratchDir dir("build-full");
  const auto full = dir / "full.db", clean = dir / "clean.db";
  const std::vector<std::string> args = {"--entries", "24", "--families", "box,cone,shard",
                                         "--modes",   "4",  "--threads",  "1",
                                         "--batch",   "2",  "--quiet"};
  // No file may grow past 300 kB (the finished file is ~2 MB): a disk that fills up mid-build.
  std::vector<std::string> build = {"build", full.string()};
  build.insert(build.end(), args.begin(), args.end());
  const test::ProcessResult failed = test::runProcess(SHAPEDB_CLI, build, {.fileSizeLimit = 300'000});
  ASSERT_NE(failed.exitCode, test::kSetupFailedExit) << "could not set RLIMIT_FSIZE";
  EXPECT_EQ(failed.exitCode, 1) << failed.err;
  EXPECT_NE(failed.err.find(full.string() + ": "), std::string::npos) << failed.err;
  EXPECT_NE(failed.err.find("is the disk full?"), std::string::npos) << failed.err;
  const std::size_t kept = committedEntries(full);
  std::printf("the full disk stopped the build with %zu of 24 entries committed\n", kept);
  EXPECT_GE(kept, 2u);
  EXPECT_LT(kept, 24u);

  // Room again: the build resumes and ends as a clean build does.
  const test::ProcessResult resumed =
      test::runProcess(SHAPEDB_CLI, {"build", full.string(), "--resume", "--quiet"});
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  std::vector<std::string> cleanBuild = {"build", clean.string()};
  cleanBuild.insert(cleanBuild.end(), args.begin(), args.end());
  ASSERT_EQ(test::runProcess(SHAPEDB_CLI, cleanBuild).exitCode, 0);
  EXPECT_EQ(committedEntries(full), 24u);
  expectSameEntries(full, clean);
}

TEST(BuildCli, AReadOnlyDatabaseIsQueriedAndWritesAreRefusedWithNothingChanged) {
  test::ScratchDir dir("build-readonly");
  const auto folder = dir / "shipped";
  std::filesystem::create_directories(folder);
  const auto db = folder / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 4, "box", 2).exitCode, 0);
  const auto mesh = dir / "box.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.3, 0.2, 0.1}), mesh).ok());
  const std::string before = dumpEntries(db);
  // A shipped database: the file and its folder read-only (as on a read-only medium).
  namespace fs = std::filesystem;
  fs::permissions(db, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const test::RunOptions readOnly{.obeyFilePermissions = true};

  const test::ProcessResult query =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), mesh.string(), "--json"}, readOnly);
  ASSERT_NE(query.exitCode, test::kSetupFailedExit)
      << "could not drop the capabilities that override permissions";
  EXPECT_EQ(query.exitCode, 0) << query.err;
  EXPECT_EQ(nlohmann::json::parse(query.out)["queries"][0]["matches"][0]["family"], "box");
  const test::ProcessResult info = test::runProcess(SHAPEDB_CLI, {"info", db.string()}, readOnly);
  EXPECT_EQ(info.exitCode, 0) << info.err;

  for (const std::vector<std::string>& write :
       {std::vector<std::string>{"add", db.string(), mesh.string()},
        std::vector<std::string>{"build", db.string(), "--resume", "--quiet"}}) {
    const test::ProcessResult refused = test::runProcess(SHAPEDB_CLI, write, readOnly);
    EXPECT_EQ(refused.exitCode, 1) << write[0] << ": " << refused.err;
    EXPECT_NE(refused.err.find(db.string() + ": the file is read-only"), std::string::npos) << refused.err;
  }
  fs::permissions(folder, fs::perms::owner_all);
  fs::permissions(db, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_TRUE(dumpEntries(db) == before) << "a refused write changed the file";
  EXPECT_FALSE(fs::exists(db.string() + "-wal"));
}

TEST(BuildCli, InfoAndAddEndToEnd) {
  test::ScratchDir dir("build-info");
  const auto db = dir / "small.db";
  test::ProcessResult built = test::buildWithCli(db, 4, "box,prism", 3);
  ASSERT_EQ(built.exitCode, 0) << built.err;
  EXPECT_NE(built.out.find("4 entries built"), std::string::npos) << built.out;

  const auto mesh = dir / "wedge.obj";
  ASSERT_TRUE(io::saveMesh(core::makeTriangularPrism(1.0, 0.3, 2.0), mesh).ok());
  test::ProcessResult added = test::runProcess(SHAPEDB_CLI, {"add", db.string(), mesh.string()});
  ASSERT_EQ(added.exitCode, 0) << added.err;
  EXPECT_NE(added.out.find("added as entry 4"), std::string::npos) << added.out;
  EXPECT_NE(added.err.find("[1/1] " + mesh.string() + ": "), std::string::npos) << added.err;  // progress
  EXPECT_NE(added.err.find(" tets, 3 modes in "), std::string::npos) << added.err;

  test::ProcessResult info = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--json"});
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const nlohmann::json j = nlohmann::json::parse(info.out);
  EXPECT_EQ(j["entries"], 5);
  EXPECT_EQ(j["families"]["box"], 2);
  EXPECT_EQ(j["families"]["prism"], 2);
  EXPECT_EQ(j["families"]["user"], 1);
  EXPECT_EQ(j["status"], "complete");
  EXPECT_EQ(j["parameters"]["modes"]["count"], 3);
  EXPECT_GT(j["size_bytes"].get<double>(), 0.0);

  test::ProcessResult text = test::runProcess(SHAPEDB_CLI, {"info", db.string()});
  EXPECT_EQ(text.exitCode, 0);
  EXPECT_NE(text.out.find("entries: 5"), std::string::npos) << text.out;

  // Bad inputs: a mesh that does not exist, a file that is not a database, an unknown family.
  test::ProcessResult missing =
      test::runProcess(SHAPEDB_CLI, {"add", db.string(), (dir / "none.obj").string()});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("none.obj"), std::string::npos) << missing.err;
  test::ProcessResult notDb = test::runProcess(SHAPEDB_CLI, {"info", mesh.string()});
  EXPECT_EQ(notDb.exitCode, 1);
  EXPECT_NE(notDb.err.find("not a database"), std::string::npos) << notDb.err;
  // A surface that passes through itself (two boxes that overlap, written as one mesh): refused with the
  // triangles that cross and the flag that remeshes it, and nothing added.
  const auto crossed = dir / "crossed.obj";
  ASSERT_TRUE(io::saveMesh(test::twoUnitBoxes({0.5, 0.3, 0.2}), crossed).ok());
  test::ProcessResult refused = test::runProcess(SHAPEDB_CLI, {"add", db.string(), crossed.string()});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("crossed.obj"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("passes through itself"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--repair"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("[1/1] " + crossed.string() + ": failed, so none will be added"),
            std::string::npos)
      << refused.err;
  // Two boxes apart, as one mesh: two solids, where an entry is one (its tets would make two pieces,
  // ringing at zero); refused, with the remeshing flag as what may get past it (solids that touch are one
  // once remeshed as the solid they enclose together).
  const auto twoPieces = dir / "apart.obj";
  ASSERT_TRUE(io::saveMesh(test::twoUnitBoxes({3.0, 0.0, 0.0}), twoPieces).ok());
  test::ProcessResult pieces = test::runProcess(SHAPEDB_CLI, {"add", db.string(), twoPieces.string()});
  EXPECT_EQ(pieces.exitCode, 1);
  EXPECT_NE(pieces.err.find("2 separate solids"), std::string::npos) << pieces.err;
  EXPECT_NE(pieces.err.find("; --repair remeshes the surface as the solid it encloses"), std::string::npos)
      << pieces.err;
  test::ProcessResult after = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--json"});
  ASSERT_EQ(after.exitCode, 0) << after.err;
  EXPECT_EQ(nlohmann::json::parse(after.out)["entries"], 5);

  test::ProcessResult family =
      test::runProcess(SHAPEDB_CLI, {"build", (dir / "x.db").string(), "--families", "torus"});
  EXPECT_EQ(family.exitCode, 2);
  EXPECT_NE(family.err.find("unknown family 'torus'"), std::string::npos) << family.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.db"));
}

// A fine surface is meshed through its simplification unless told otherwise, with a note that says so.
// (Fewer triangles are not always fewer tets: TetGen's quality bound refines a sphere's simplified,
// longer triangles further than the round ones. A scan of 10⁵ triangles is where it tells.)
TEST(BuildCli, AddSimplifiesAFineSurfaceBeforeItsTets) {
  test::ScratchDir dir("build-add-fine");
  const auto db = dir / "small.db";
  test::ProcessResult built = test::buildWithCli(db, 2, "box", 3);
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const core::TriangleMesh ball = core::makeIcosphere(0.1, 3);  // 1,280 triangles
  ASSERT_TRUE(io::saveMesh(ball, dir / "ball.obj").ok());
  ASSERT_TRUE(io::saveMesh(ball, dir / "ball_as_given.obj").ok());

  test::ProcessResult simplified = test::runProcess(
      SHAPEDB_CLI, {"add", db.string(), (dir / "ball.obj").string(), "--max-triangles", "300"});
  ASSERT_EQ(simplified.exitCode, 0) << simplified.err;
  EXPECT_NE(simplified.err.find("its 1280 triangles are simplified to at most 300"), std::string::npos)
      << simplified.err;
  test::ProcessResult asGiven = test::runProcess(
      SHAPEDB_CLI, {"add", db.string(), (dir / "ball_as_given.obj").string(), "--max-triangles", "0"});
  ASSERT_EQ(asGiven.exitCode, 0) << asGiven.err;
  EXPECT_EQ(asGiven.err.find("simplified"), std::string::npos) << asGiven.err;

  auto store = io::Store::open(db);
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto entries = store->entries();
  ASSERT_TRUE(entries.ok());
  std::size_t simplifiedTets = 0, asGivenTets = 0;
  for (const io::EntryRecord& e : *entries) {
    if (e.name == "ball.obj") simplifiedTets = e.tets;
    if (e.name == "ball_as_given.obj") asGivenTets = e.tets;
  }
  EXPECT_GT(simplifiedTets, 0u);
  EXPECT_GT(asGivenTets, 0u);
  EXPECT_NE(simplifiedTets, asGivenTets);  // the same surface meshed twice would give the same tets
}

TEST(BuildCli, QuadraticTetsEndToEnd) {
  test::ScratchDir dir("build-quadratic");
  const auto db = dir / "quadratic.db";
  test::ProcessResult built =
      test::runProcess(SHAPEDB_CLI, {"build", db.string(), "--entries", "2", "--families", "box", "--modes",
                                     "4", "--elements", "quadratic", "--quiet"});
  ASSERT_EQ(built.exitCode, 0) << built.err;
  test::ProcessResult info = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--json"});
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const nlohmann::json parameters = nlohmann::json::parse(info.out)["parameters"];
  EXPECT_EQ(parameters["modes"]["elements"], "quadratic");
  EXPECT_EQ(parameters["tetgen"]["max_radius_edge_ratio"], 3.0);
  test::ProcessResult text = test::runProcess(SHAPEDB_CLI, {"info", db.string()});
  EXPECT_NE(text.out.find("on quadratic tets"), std::string::npos) << text.out;

  // The first box entry's own surface, queried in unit material: its frequencies are those of quadratic
  // tets computed directly on the same surface (same TetGen options, so the same mesh).
  const core::TriangleMesh surface = *volume::makeFamilyShape(volume::familySpec(volume::Family::kBox, 0));
  std::filesystem::create_directories(dir / "queries");
  const auto mesh = dir / "queries" / "box.ply";
  ASSERT_TRUE(io::saveMesh(surface, mesh).ok());
  test::ProcessResult q = test::runProcess(SHAPEDB_CLI, {"query", db.string(), mesh.string(), "--density",
                                                         "1", "--youngs", "1", "--poisson", "0.3", "--json"});
  ASSERT_EQ(q.exitCode, 0) << q.err;
  const nlohmann::json physics = nlohmann::json::parse(q.out)["queries"][0]["physics"];
  const volume::EntryOptions options = volume::withElements({}, volume::ElementOrder::kQuadratic);
  auto tets = volume::tetrahedralize(surface, options.tetgen);
  ASSERT_TRUE(tets.ok()) << tets.error().message;
  auto direct = volume::computeModes(
      *tets, {.modes = 4, .material = core::unitMaterial(), .order = volume::ElementOrder::kQuadratic});
  ASSERT_TRUE(direct.ok()) << direct.error().message;
  ASSERT_EQ(physics["frequencies_hz"].size(), 4u);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(physics["frequencies_hz"][static_cast<std::size_t>(i)].get<double>(),
                direct->frequenciesHz()[i], 1e-6 * direct->frequenciesHz()[i])
        << "mode " << i;

  // The stretch correction is for linear tets: a clear refusal, not a wrong answer.
  test::ProcessResult stretched =
      test::runProcess(SHAPEDB_CLI, {"query", db.string(), mesh.string(), "--stretch"});
  EXPECT_NE(stretched.exitCode, 0);
  EXPECT_NE(stretched.err.find("needs a database of linear tets"), std::string::npos) << stretched.err;
  // The benchmark leaves the stretched column empty, not a copy of the uniform one.
  test::ProcessResult bench =
      test::runProcess(SHAPEDB_CLI, {"bench", db.string(), "--queries", (dir / "queries").string(), "--out",
                                     (dir / "bench").string(), "--frequencies", "4"});
  ASSERT_EQ(bench.exitCode, 0) << bench.err;
  const std::string summary = test::readFile(dir / "bench" / "summary.md");
  EXPECT_NE(summary.find("quadratic tets), steel; truth and baselines on quadratic tets"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("| centroid-voxel | 1 |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("| centroid-voxel-stretched | 0 | n/a |"), std::string::npos) << summary;

  // An unknown order, and a resume that would change it.
  test::ProcessResult cubic =
      test::runProcess(SHAPEDB_CLI, {"build", (dir / "x.db").string(), "--elements", "cubic"});
  EXPECT_EQ(cubic.exitCode, 2);
  EXPECT_NE(cubic.err.find("linear or quadratic, not 'cubic'"), std::string::npos) << cubic.err;
  test::ProcessResult resumed =
      test::runProcess(SHAPEDB_CLI, {"build", db.string(), "--resume", "--elements", "linear", "--quiet"});
  EXPECT_EQ(resumed.exitCode, 2);
  EXPECT_NE(resumed.err.find("another elements"), std::string::npos) << resumed.err;
}

// The wall bound reaches TetGen: the entry's tets are those of the beam's surface meshed with it, more
// than without it; it is stored with the parameters, and a resume that would change it is refused.
TEST(BuildCli, TheWallBoundIsABuildParameter) {
  test::ScratchDir dir("build-wall");
  const auto db = dir / "walled.db";
  test::ProcessResult built =
      test::runProcess(SHAPEDB_CLI, {"build", db.string(), "--entries", "1", "--families", "beam", "--modes",
                                     "4", "--wall-edge-fraction", "0.7", "--quiet"});
  ASSERT_EQ(built.exitCode, 0) << built.err;
  test::ProcessResult info = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--json"});
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const nlohmann::json summary = nlohmann::json::parse(info.out);
  EXPECT_EQ(summary["parameters"]["tetgen"]["wall_edge_fraction"], 0.7);

  const core::TriangleMesh surface = *volume::makeFamilyShape(volume::familySpec(volume::Family::kBeam, 0));
  volume::TetrahedralizeOptions options = volume::entryMeshing(volume::ElementOrder::kQuadratic);
  const auto without = volume::tetrahedralize(surface, options);
  options.wallEdgeFraction = 0.7;
  const auto with = volume::tetrahedralize(surface, options);
  ASSERT_TRUE(without.ok() && with.ok());
  EXPECT_EQ(summary["mean_tets"].get<double>(), static_cast<double>(with->tetCount()));
  EXPECT_GT(with->tetCount(), without->tetCount());
  test::ProcessResult text = test::runProcess(SHAPEDB_CLI, {"info", db.string()});
  EXPECT_NE(text.out.find("edges ≤ 0.7 of the wall thickness"), std::string::npos) << text.out;

  test::ProcessResult resumed = test::runProcess(
      SHAPEDB_CLI, {"build", db.string(), "--resume", "--wall-edge-fraction", "0.3", "--quiet"});
  EXPECT_EQ(resumed.exitCode, 2);
  EXPECT_NE(resumed.err.find("wall-edge-fraction"), std::string::npos) << resumed.err;
}

/// Runs one SQL statement on a database file with SQLite itself, as someone who edited the file would.
void execSql(const std::filesystem::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  char* message = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message), SQLITE_OK) << (message ? message : "");
  sqlite3_free(message);
  sqlite3_close(db);
}

// A database from elsewhere is untrusted: one with a trigger, a view or a table that shapedb does not
// create is refused by every command that opens it, by name, and nothing in it changes.
TEST(UntrustedDatabase, ATriggerViewOrExtraTableIsRefusedAndTheFileLeftUnchanged) {
  test::ScratchDir dir("untrusted");
  const auto clean = dir / "clean.db";
  ASSERT_EQ(test::buildWithCli(clean, 2, "box", 2).exitCode, 0);
  const auto mesh = dir / "box.obj";
  ASSERT_TRUE(io::saveMesh(core::makeBox({0.3, 0.2, 0.1}), mesh).ok());
  const std::vector<std::pair<std::string, std::string>> additions = {
      {"trigger 'grow'", "CREATE TRIGGER grow AFTER INSERT ON entries BEGIN DELETE FROM meta; END"},
      {"view 'everything'", "CREATE VIEW everything AS SELECT * FROM entries"},
      {"table 'notes'", "CREATE TABLE notes(text TEXT)"},
      {"index 'by_family'", "CREATE INDEX by_family ON entries(family)"}};
  for (const auto& [object, sql] : additions) {
    SCOPED_TRACE(object);
    const auto db = dir / "edited.db";
    std::filesystem::copy_file(clean, db, std::filesystem::copy_options::overwrite_existing);
    execSql(db, sql);
    const std::string before = test::readFile(db);
    for (const std::vector<std::string>& command :
         {std::vector<std::string>{"info", db.string()},
          std::vector<std::string>{"query", db.string(), mesh.string()},
          std::vector<std::string>{"add", db.string(), mesh.string()}}) {
      const test::ProcessResult r = test::runProcess(SHAPEDB_CLI, command);
      EXPECT_EQ(r.exitCode, 1) << command[0] << ": " << r.err;
      EXPECT_NE(r.err.find(db.string() + ": holds " + object + ", which shapedb does not create"),
                std::string::npos)
          << command[0] << ": " << r.err;
    }
    EXPECT_TRUE(test::readFile(db) == before) << "a refused file changed";
  }
  // The clean file itself is read as ever.
  EXPECT_EQ(test::runProcess(SHAPEDB_CLI, {"info", clean.string()}).exitCode, 0);
}

// info --check: SQLite's integrity check and every blob's checksum; a byte flipped inside one entry's
// modes is found, and the entry named.
TEST(InfoCli, CheckFindsAByteFlippedInsideABlobAndNamesTheEntry) {
  test::ScratchDir dir("check");
  const auto db = dir / "small.db";
  ASSERT_EQ(test::buildWithCli(db, 3, "box", 2).exitCode, 0);
  const test::ProcessResult good = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--check", "--json"});
  ASSERT_EQ(good.exitCode, 0) << good.err;
  const nlohmann::json report = nlohmann::json::parse(good.out)["check"];
  EXPECT_TRUE(report["ok"].get<bool>());
  EXPECT_EQ(report["blobs_checked"].get<int>(), 3 * (3 + 5));  // three descriptors, five physics parts
  EXPECT_TRUE(report["damaged"].empty());

  // The middle byte of box-00001's modes, its bits flipped in place (SQLite's incremental blob I/O: the
  // blob keeps its size and its stored checksum).
  {
    sqlite3* handle = nullptr;
    ASSERT_EQ(sqlite3_open_v2(db.c_str(), &handle, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
    sqlite3_stmt* row = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(handle,
                                 "SELECT p.rowid FROM physics p JOIN entries e ON e.id = p.entry_id "
                                 "WHERE e.name = 'box-00001' AND p.part = 2",
                                 -1, &row, nullptr),
              SQLITE_OK);
    ASSERT_EQ(sqlite3_step(row), SQLITE_ROW);
    const sqlite3_int64 rowid = sqlite3_column_int64(row, 0);
    sqlite3_finalize(row);
    sqlite3_blob* blob = nullptr;
    ASSERT_EQ(sqlite3_blob_open(handle, "main", "physics", "data", rowid, 1, &blob), SQLITE_OK);
    const int middle = sqlite3_blob_bytes(blob) / 2;
    unsigned char byte = 0;
    ASSERT_EQ(sqlite3_blob_read(blob, &byte, 1, middle), SQLITE_OK);
    byte = static_cast<unsigned char>(~byte);
    ASSERT_EQ(sqlite3_blob_write(blob, &byte, 1, middle), SQLITE_OK);
    sqlite3_blob_close(blob);
    sqlite3_close(handle);
  }
  const test::ProcessResult bad = test::runProcess(SHAPEDB_CLI, {"info", db.string(), "--check"});
  EXPECT_EQ(bad.exitCode, 1) << bad.out << bad.err;
  EXPECT_NE(bad.out.find("1 damaged"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("damaged: box-00001"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("modes does not match its checksum"), std::string::npos) << bad.out;
}

}  // namespace
}  // namespace shapedb::cli
