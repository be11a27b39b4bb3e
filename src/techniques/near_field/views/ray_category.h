// Names of the RSM lookup categories (NF_CAT_* in shaders/near_field/near_field_shared.h), shared
// by the category image's visualiser and the probed ray's record view (ray_category.cpp).
#pragma once

namespace voxlab {

// "valid", "no hit", "behind light / not in RSM", ...; "not a category" outside 0..NF_CATEGORIES-1.
const char* rsmLookupCategoryName(int category);
// One line saying what the category means.
const char* rsmLookupCategoryMeaning(int category);

}  // namespace voxlab
