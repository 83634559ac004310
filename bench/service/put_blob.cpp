// Puts a file into a colorlabd state directory's blob store as a kept frame of an existing run,
// through the store's own code (file durable first, then its rows in one transaction), so the
// service bench can serve a blob of any size. Prints {"sha256", "path", "size"}.
//   bench_service_put_blob STATE_DIR RUN_ID FILE
#include <iostream>

#include <nlohmann/json.hpp>

#include "colorlab/core/error.hpp"
#include "colorlab/core/ids.hpp"
#include "colorlab/store/blob_index.hpp"
#include "colorlab/store/blob_store.hpp"
#include "colorlab/store/sqlite.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: bench_service_put_blob STATE_DIR RUN_ID FILE\n";
    return 2;
  }
  try {
    std::filesystem::path state = argv[1];
    colorlab::store::BlobStore blobs(state / "blobs");
    std::string sha = blobs.put_file(argv[3]);
    auto size = std::filesystem::file_size(argv[3]);
    colorlab::store::Database db((state / "colorlab.db").string(), false);
    db.exec("PRAGMA busy_timeout = 10000");
    colorlab::store::Transaction tx(db);
    colorlab::store::insert_step_blobs(
        db, argv[2], "bench/blob",
        {colorlab::store::StepBlob{sha, "bench-" + sha.substr(0, 12), "raw", "application/octet-stream", size, {}}},
        colorlab::now_iso8601());
    tx.commit();
    std::cout << nlohmann::json{{"sha256", sha}, {"path", blobs.path_of(sha).string()}, {"size", size}}.dump() << "\n";
    return 0;
  } catch (const colorlab::Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
}
