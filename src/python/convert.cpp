// NumPy ⇄ Eigen for the Python module: strict about dtypes and dimensions,
// zero-copy for contiguous float64 input and for results.
#include <cstring>

#include "bindings.hpp"

namespace zwang::python {

namespace {

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

// float64 in the machine's byte order (a '>f8' array is converted, not read in place).
bool isNativeFloat64(const py::array& a) { return py::isinstance<py::array_t<double>>(a); }

// Any input as a NumPy array with a real (int, unsigned, float) dtype.
py::array realArray(const char* name, py::handle value) {
  if (value.is_none()) raise(PyExc_TypeError, std::string(name) + ": expected an array of real numbers, got None");
  py::array a = py::isinstance<py::array>(value) ? py::reinterpret_borrow<py::array>(value) : py::array::ensure(value);
  if (!a) {
    PyErr_Clear();
    raise(PyExc_TypeError, std::string(name) + ": expected an array of real numbers, got " +
                               std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  }
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    raise(PyExc_TypeError, std::string(name) + ": expected real numbers (float64), got dtype " +
                               std::string(py::str(a.dtype())) +
                               (kind == 'c' ? " (complex values are not accepted)" : ""));
  return a;
}

// Copy a real 1-D array (any dtype, any stride) into out.
void copyReal(const char* name, const py::array& a, double* out) {
  const py::ssize_t n = a.shape(0);
  if (isNativeFloat64(a)) {
    const auto* base = static_cast<const char*>(a.data());
    const py::ssize_t stride = a.strides(0);
    for (py::ssize_t k = 0; k < n; ++k) std::memcpy(out + k, base + k * stride, sizeof(double));
    return;
  }
  py::array_t<double, py::array::forcecast> converted = py::array_t<double, py::array::forcecast>::ensure(a);
  if (!converted) {
    PyErr_Clear();
    raise(PyExc_TypeError,
          std::string(name) + ": cannot convert dtype " + std::string(py::str(a.dtype())) + " to float64");
  }
  const auto view = converted.unchecked<1>();
  for (py::ssize_t k = 0; k < n; ++k) out[k] = view(k);
}

py::array vectorArray(const char* name, py::handle value) {
  py::array a = realArray(name, value);
  if (a.ndim() != 1) raise(PyExc_ValueError, std::string(name) + ": expected a 1-D array, got shape " + shapeText(a));
  return a;
}

template <int N>
Eigen::Matrix<double, N, 1> fixedArg(const char* name, py::handle value) {
  const py::array a = vectorArray(name, value);
  if (a.shape(0) != N)
    raise(PyExc_ValueError,
          std::string(name) + ": expected " + std::to_string(N) + " numbers, got shape " + shapeText(a));
  Eigen::Matrix<double, N, 1> v;
  copyReal(name, a, v.data());
  return v;  // finiteness is checked by the C++ solve (a Status naming the value)
}

}  // namespace

Eigen::Map<const Eigen::VectorXd> vectorArg(const char* name, py::handle value, Eigen::VectorXd& buffer) {
  const py::array a = vectorArray(name, value);
  const py::ssize_t n = a.shape(0);
  // In place only when `value` itself is the array: an array made here from a
  // list dies with `a`, so its numbers are copied into the buffer.
  if (a.ptr() == value.ptr() && isNativeFloat64(a) && (a.strides(0) == 8 || n <= 1))
    return {static_cast<const double*>(a.data()), n};  // in place, no copy
  if (buffer.size() != n) buffer.resize(n);
  copyReal(name, a, buffer.data());
  return {buffer.data(), n};
}

Eigen::MatrixXd matrixArg(const char* name, py::handle value, int rows, int cols) {
  const py::array a = realArray(name, value);
  if (a.ndim() != 2 || a.shape(0) != rows || a.shape(1) != cols)
    raise(PyExc_ValueError, std::string(name) + ": expected a " + std::to_string(rows) + "×" + std::to_string(cols) +
                                " matrix, got shape " + shapeText(a));
  using RowMajor = py::array_t<double, py::array::c_style | py::array::forcecast>;
  RowMajor converted = RowMajor::ensure(a);
  if (!converted) {
    PyErr_Clear();
    raise(PyExc_TypeError,
          std::string(name) + ": cannot convert dtype " + std::string(py::str(a.dtype())) + " to float64");
  }
  const auto view = converted.unchecked<2>();
  Eigen::MatrixXd M(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = view(i, j);
  return M;
}

Vec3 vec3Arg(const char* name, py::handle value) { return fixedArg<3>(name, value); }
Vec6 vec6Arg(const char* name, py::handle value) { return fixedArg<6>(name, value); }

ConstraintMatrix constraintMatrixArg(const char* name, py::handle value) {
  const py::array a = realArray(name, value);
  if (a.ndim() == 1 && a.shape(0) == 6) {
    ConstraintMatrix A(6, 1);
    copyReal(name, a, A.data());
    if (!A.allFinite()) raise(PyExc_ValueError, std::string(name) + ": holds a non-finite value (NaN or Inf)");
    return A;
  }
  if (a.ndim() != 2 || a.shape(0) != 6 || a.shape(1) < 1)
    raise(PyExc_ValueError, std::string(name) +
                                ": expected a 6×m matrix (columns are unit constraint forces, linear part first) "
                                "or one 6-vector, got shape " +
                                shapeText(a));
  py::array_t<double, py::array::forcecast> converted = py::array_t<double, py::array::forcecast>::ensure(a);
  if (!converted) {
    PyErr_Clear();
    raise(PyExc_TypeError, std::string(name) + ": cannot convert to float64");
  }
  const auto view = converted.unchecked<2>();
  ConstraintMatrix A(6, a.shape(1));
  for (py::ssize_t r = 0; r < 6; ++r)
    for (py::ssize_t c = 0; c < a.shape(1); ++c) A(r, c) = view(r, c);
  if (!A.allFinite()) raise(PyExc_ValueError, std::string(name) + ": holds a non-finite value (NaN or Inf)");
  return A;
}

Expressed expressedArg(const char* name, const std::string& text, bool allow_aligned, bool allow_reference) {
  const problem::AxesOf axes = !allow_aligned     ? problem::AxesOf::Wrench
                               : !allow_reference ? problem::AxesOf::Constraint
                                                  : problem::AxesOf::RelativeConstraint;
  return checked(name, [&] { return problem::parseExpressed(kPython, text, axes); });
}

const char* expressedName(Expressed e) {
  switch (e) {
    case Expressed::Local: return "local";
    case Expressed::World: return "world";
    case Expressed::Reference: return "reference";
  }
  return "world";
}

py::array vectorView(const double* data, Eigen::Index size, py::handle base, bool writeable) {
  if (size == 0) return py::array_t<double>(0);
  py::array a(py::dtype::of<double>(), {size}, {static_cast<py::ssize_t>(sizeof(double))}, data, base);
  if (!writeable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array vectorView(const Eigen::VectorXd& v, py::handle base, bool writeable) {
  return vectorView(v.data(), v.size(), base, writeable);
}

py::array matrixView(const Eigen::MatrixXd& m, py::handle base) {
  if (m.size() == 0) return py::array_t<double>(std::vector<py::ssize_t>{m.rows(), m.cols()});
  const auto s = static_cast<py::ssize_t>(sizeof(double));
  py::array a(py::dtype::of<double>(), {m.rows(), m.cols()}, {s, s * m.rows()}, m.data(), base);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array vectorCopy(const Eigen::Ref<const Eigen::VectorXd>& v) {
  py::array_t<double> a(v.size());
  if (v.size() > 0) std::memcpy(a.mutable_data(), v.data(), static_cast<std::size_t>(v.size()) * sizeof(double));
  return std::move(a);
}

py::array matrixCopy(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  py::array_t<double> a(std::vector<py::ssize_t>{m.rows(), m.cols()});
  auto out = a.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) out(r, c) = m(r, c);
  return std::move(a);
}

}  // namespace zwang::python
