//! `dnnevo._core.Fleet`: many robots in one 2-D world, one per row, stepped together for a
//! closed-loop task ([`sim2d::Fleet`]). The settings are parsed and validated once, into the
//! object Python holds; arrays cross as NumPy, and every bad argument is an
//! `InvalidArgumentError` that names it.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyString};
use rayon::prelude::*;
use serde_json::{Map, Value};

use crate::arrays::{arg_err, dense, shape_str, to_numpy, AnyInt};
use crate::json::to_py;
use crate::pyjson::dict_to_map;

/// Rows stepped by one task of the thread pool; fewer rows than this are stepped in place.
const CHUNK: usize = 16;

/// B robots in one 2-D world, one per row, stepped together: the world of a closed-loop robot
/// task (``dnnevo.robots.RobotWorld`` wraps it).
///
/// ``Fleet(world, settings=None)``: ``world`` is a world file's TOML text or a world as a dict
/// (``sim2d_landmark_world(1)``); ``settings`` a dict of ``dt``, ``robot``, ``sonar``,
/// ``pursuers``, ``sectors`` and ``start_clearance`` (docs/robots.md), every one left out at
/// its default.
///
/// - ``reset(episodes, seed)`` starts one row per episode number, from random starts drawn
///   from ``(seed, episode)``; ``place(poses, pursuers=None)`` puts them by hand.
/// - ``step(wheels, active=None)`` moves every active row's robot with its wheel speeds (B, 2)
///   in m/s, then its pursuers, and reads the sensors. The GIL is released; rows run on all
///   cores, with the same bits for any number of threads.
/// - ``poses`` (B, 3), ``contacts`` (B,), ``captured`` (B,), ``ranges`` (B, S), ``sectors``
///   (B, Q) and ``pursuers`` (B, K, 3) are copies of the rows' state.
///
/// >>> from dnnevo import _core
/// >>> fleet = _core.Fleet(_core.sim2d_landmark_world(1), {"sonar": {"angles_deg": [0, 90]}})
/// >>> fleet.reset([0, 1, 0], seed=5)
/// >>> fleet.step([[0.3, 0.3]] * 3)
/// >>> fleet.ranges.shape, bool((fleet.poses[0] == fleet.poses[2]).all())
/// ((3, 2), True)
#[pyclass(module = "dnnevo._core", name = "Fleet")]
pub struct PyFleet {
    inner: sim2d::Fleet,
}

fn invalid(e: sim2d::Error) -> PyErr {
    arg_err(e.to_string())
}

/// The world from TOML text or a dict.
fn world_spec(world: &Bound<'_, PyAny>) -> PyResult<sim2d::WorldSpec> {
    if let Ok(text) = world.cast::<PyString>() {
        return sim2d::WorldSpec::from_toml_str(&text.to_cow()?).map_err(invalid);
    }
    let map = dict_to_map(world, "world").map_err(|e| {
        arg_err(format!(
            "world is of type {}; expected a world file's TOML text or a dict ({})",
            world
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default(),
            e.value(world.py())
        ))
    })?;
    // An error names the field, as a world file's does: `world.boxes[0].size: ...`.
    serde_path_to_error::deserialize(Value::Object(map)).map_err(|e| {
        let path = e.path().to_string();
        match path.as_str() {
            "." => arg_err(format!("world: {}", e.inner())),
            _ => arg_err(format!("world.{path}: {}", e.inner())),
        }
    })
}

/// The settings from a dict; an error names the field (`settings.robot.radius: ...`).
fn fleet_spec(settings: Option<&Bound<'_, PyAny>>) -> PyResult<sim2d::FleetSpec> {
    let Some(settings) = settings.filter(|s| !s.is_none()) else {
        return Ok(sim2d::FleetSpec::default());
    };
    let map = dict_to_map(settings, "settings")
        .map_err(|e| arg_err(e.value(settings.py()).to_string()))?;
    serde_json::from_value(Value::Object(map.clone())).map_err(|e| arg_err(locate(&map, e)))
}

/// Which field of `map` a deserialisation error is about: each top-level field, and each
/// field of a section, is read alone (every other field at its default) until one fails.
fn locate(map: &Map<String, Value>, whole: serde_json::Error) -> String {
    let alone = |v: Value| serde_json::from_value::<sim2d::FleetSpec>(v).err();
    for (key, value) in map {
        let Some(e) = alone(Value::Object(Map::from_iter([(
            key.clone(),
            value.clone(),
        )]))) else {
            continue;
        };
        if let Value::Object(section) = value {
            for (field, v) in section {
                let one = Map::from_iter([(field.clone(), v.clone())]);
                let top = Map::from_iter([(key.clone(), Value::Object(one))]);
                if let Some(e) = alone(Value::Object(top)) {
                    return format!("settings.{key}.{field}: {e}");
                }
            }
        }
        return format!("settings.{key}: {e}");
    }
    format!("settings: {whole}")
}

/// A (rows, columns) float64 copy of an array-like, or an error naming `name` and the shape
/// expected.
fn matrix(obj: &Bound<'_, PyAny>, name: &str, rows: usize, columns: usize) -> PyResult<Vec<f64>> {
    let d = dense(obj, name, arg_err)?;
    if d.shape != [rows, columns] {
        return Err(arg_err(format!(
            "{name} has shape {}; expected ({rows}, {columns})",
            shape_str(&d.shape)
        )));
    }
    Ok(d.data)
}

/// Poses from an array-like of x, y, heading triples of the given shape ((B, 3) or (B, K, 3)).
fn poses(obj: &Bound<'_, PyAny>, name: &str, shape: &[usize]) -> PyResult<Vec<sim2d::Pose>> {
    let d = dense(obj, name, arg_err)?;
    if d.shape != shape {
        return Err(arg_err(format!(
            "{name} has shape {}; expected {}",
            shape_str(&d.shape),
            shape_str(shape)
        )));
    }
    Ok(d.data
        .chunks_exact(3)
        .map(|p| sim2d::Pose::new(p[0], p[1], p[2]))
        .collect())
}

/// A bool mask of `rows` entries from a NumPy bool array or a sequence of bools; other dtypes
/// are refused rather than cast.
fn mask(obj: &Bound<'_, PyAny>, name: &str, rows: usize) -> PyResult<Vec<bool>> {
    if let Ok(a) = obj.cast::<PyArray1<bool>>() {
        if a.len() == rows {
            return Ok(a.to_vec()?);
        }
    }
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if kind != "b" || shape != [rows] {
        return Err(arg_err(format!(
            "{name} is an array of dtype {} and shape {}; expected booleans of shape ({rows},), one per row",
            arr.getattr("dtype")?.str()?,
            shape_str(&shape)
        )));
    }
    arr.call_method0("tolist")?.extract()
}

/// Episode numbers: a 1-D array-like of integers >= 0.
fn episodes(obj: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    let empty = shape == [0];
    if shape.len() != 1 || !(kind == "i" || kind == "u" || empty) {
        return Err(arg_err(format!(
            "episodes is an array of dtype {} and shape {}; expected a 1-D array of episode numbers >= 0",
            arr.getattr("dtype")?.str()?,
            shape_str(&shape)
        )));
    }
    let values: Vec<i128> = arr.call_method0("tolist")?.extract()?;
    values
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            u64::try_from(e).map_err(|_| {
                arg_err(format!(
                    "episodes[{i}] is {e}; it must be an integer in [0, 2**64)"
                ))
            })
        })
        .collect()
}

impl PyFleet {
    fn column<'py, T: Copy + numpy::Element>(
        &self,
        py: Python<'py>,
        f: impl Fn(&sim2d::Row) -> T,
    ) -> Bound<'py, PyArray1<T>> {
        PyArray1::from_vec(py, self.inner.rows().iter().map(f).collect())
    }

    fn table<'py>(
        &self,
        py: Python<'py>,
        shape: &[usize],
        f: impl Fn(&sim2d::Row, &mut Vec<f64>),
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let mut data = Vec::with_capacity(shape.iter().product());
        for row in self.inner.rows() {
            f(row, &mut data);
        }
        to_numpy(py, data, shape)
    }
}

#[pymethods]
impl PyFleet {
    #[new]
    #[pyo3(signature = (world, settings=None))]
    fn new(world: &Bound<'_, PyAny>, settings: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let world = world_spec(world)?;
        let spec = fleet_spec(settings)?;
        Ok(PyFleet {
            inner: sim2d::Fleet::new(&world, &spec).map_err(invalid)?,
        })
    }

    /// The settings, every default filled in, as a dict.
    #[getter]
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.inner.spec())
    }

    /// The world, as a dict.
    #[getter]
    fn world<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.inner.arena().world().spec())
    }

    /// Rows B (0 before the first reset).
    #[getter]
    fn rows(&self) -> usize {
        self.inner.len()
    }

    /// Starts one row per entry of `episodes` (B integers >= 0) at random starts drawn from
    /// `seed` and each episode number; rows of the same episode start alike.
    #[pyo3(signature = (episodes, seed))]
    fn reset(&mut self, py: Python<'_>, episodes: &Bound<'_, PyAny>, seed: AnyInt) -> PyResult<()> {
        let episodes = self::episodes(episodes)?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let fleet = &mut self.inner;
        py.detach(|| fleet.reset(&episodes, seed)).map_err(invalid)
    }

    /// Puts every robot at `poses` (B, 3: x, y, heading) and, when given, its pursuers at
    /// `pursuers` (B, K, 3), and reads the sensors.
    #[pyo3(signature = (poses, pursuers=None))]
    fn place(
        &mut self,
        poses: &Bound<'_, PyAny>,
        pursuers: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let b = self.inner.len();
        let k = self.inner.spec().pursuers.count as usize;
        let robots = self::poses(poses, "poses", &[b, 3])?;
        let chasers = pursuers
            .filter(|p| !p.is_none())
            .map(|p| self::poses(p, "pursuers", &[b, k, 3]))
            .transpose()?;
        self.inner
            .place(&robots, chasers.as_deref())
            .map_err(invalid)
    }

    /// Moves every row that `active` (B bools, None for all) marks by one step with its wheel
    /// speeds `wheels` (B, 2: left, right in m/s), then reads its sensors.
    #[pyo3(signature = (wheels, active=None))]
    fn step(
        &mut self,
        py: Python<'_>,
        wheels: &Bound<'_, PyAny>,
        active: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let b = self.inner.len();
        let wheels = matrix(wheels, "wheels", b, 2)?;
        let active = active
            .filter(|a| !a.is_none())
            .map(|a| mask(a, "active", b))
            .transpose()?;
        let active = active.as_deref();
        self.inner.check_step(&wheels, active).map_err(invalid)?;
        let (arena, rows) = self.inner.split_mut();
        let step = |(c, chunk): (usize, &mut [sim2d::Row])| {
            chunk.iter_mut().enumerate().try_for_each(|(i, row)| {
                let r = c * CHUNK + i;
                if active.is_none_or(|a| a[r]) {
                    arena.step_row(row, wheels[2 * r], wheels[2 * r + 1])
                } else {
                    Ok(())
                }
            })
        };
        py.detach(|| {
            if rows.len() <= CHUNK {
                rows.chunks_mut(CHUNK).enumerate().try_for_each(step)
            } else {
                rows.par_chunks_mut(CHUNK).enumerate().try_for_each(step)
            }
        })
        .map_err(invalid)
    }

    /// Each robot's pose (B, 3): x and y in metres, heading in radians in (-pi, pi].
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.table(py, &[self.inner.len(), 3], |r, out| {
            let p = r.pose();
            out.extend([p.x, p.y, p.heading]);
        })
    }

    /// Whether a wall or box cut each robot's last step short (B,).
    #[getter]
    fn contacts<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.column(py, sim2d::Row::contact)
    }

    /// Whether a pursuer is within the capture radius of each robot (B,).
    #[getter]
    fn captured<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.column(py, sim2d::Row::captured)
    }

    /// Each row's episode number (B,).
    #[getter]
    fn episodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        self.column(py, sim2d::Row::episode)
    }

    /// The sonar ring's ranges in metres (B, S), in the order of the settings' angles.
    #[getter]
    fn ranges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let s = self.inner.spec().sonar.angles_deg.len();
        self.table(py, &[self.inner.len(), s], |r, out| {
            out.extend_from_slice(r.ranges())
        })
    }

    /// The pursuer sensor's gaps in metres (B, Q), sector 0 straight ahead.
    #[getter]
    fn sectors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let q = self.inner.spec().sectors.count as usize;
        self.table(py, &[self.inner.len(), q], |r, out| {
            out.extend_from_slice(r.sectors())
        })
    }

    /// The pursuers' poses (B, K, 3).
    #[getter]
    fn pursuers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let k = self.inner.spec().pursuers.count as usize;
        self.table(py, &[self.inner.len(), k, 3], |r, out| {
            out.extend(r.pursuers().iter().flat_map(|p| [p.x, p.y, p.heading]))
        })
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let s = self.inner.spec();
        let [w, h] = self.inner.arena().world().room();
        format!(
            "Fleet(rows={}, room={w}x{h}, sonars={}, pursuers={}, sectors={}, dt={})",
            self.inner.len(),
            s.sonar.angles_deg.len(),
            s.pursuers.count,
            s.sectors.count,
            s.dt
        )
    }
}
