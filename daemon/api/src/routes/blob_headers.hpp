#pragma once
// What a GET and a HEAD of a blob share before the body — identity, type and caching — on the bench
// (blob_routes.cpp) and on central (fleet/central/central_blob.cpp). The bytes of a name never change, so a
// client may keep them for good; an array blob carries its dtype, shape and CFA as headers.
#include <string>

#include "colorlab/http/message.hpp"
#include "colorlab/store/blob_index.hpp"

namespace colorlab::daemon {

void describe_blob(http::HttpResponse& r, const store::BlobRecord& blob, const std::string& etag);

}  // namespace colorlab::daemon
