// The dashboard's files, embedded in the binaries that serve or write it (fgsrd --http, fgsr report):
// the page (daemon/fgsrd/http/dashboard.html) and Chart.js from Debian's libjs-chart.js, read from
// its installed file at build time (nothing vendored, nothing fetched).
#pragma once

#include <string_view>

namespace fgsr::dashboard {

std::string_view page();     // dashboard.html
std::string_view chart_js(); // chart.min.js

// The page as one self-contained file for a recorded run: Chart.js inlined in place of its
// <script src="chart.min.js"></script> line, and `data_script` (a <script> element that sets
// window.FGSR_DATA) in place of the <!--FGSR_DATA--> marker.
std::string standalone_page(std::string_view data_script);

} // namespace fgsr::dashboard
