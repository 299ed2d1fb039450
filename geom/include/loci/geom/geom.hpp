// Everything in loci's geometry layer.
#pragma once

#include "loci/geom/box.hpp"
#include "loci/geom/error.hpp"
#include "loci/geom/point.hpp"
#include "loci/geom/predicates.hpp"
#include "loci/geom/segment.hpp"
