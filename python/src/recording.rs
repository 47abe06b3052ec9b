//! `magsep.open_recording`: a recording read through the streaming
//! [`RecordingReader`] (one chunk in memory at a time, whatever the file's size): metadata,
//! frames by index as numpy arrays, and every channel's messages as raw bytes.

use std::path::PathBuf;
use std::sync::Mutex;

use magsep_record::reader::trailing_message;
use magsep_record::{ParticleFrame, RawMessage, RecordError, RecordingReader, STATE_TOPIC};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

use crate::RecordingError;
use crate::convert::{from_json, json_value};

fn record_error(e: RecordError) -> PyErr {
    RecordingError::new_err(e.to_string())
}

/// An open recording (see `magsep.Recording` for the documented wrapper).
#[pyclass(module = "magsep._magsep", name = "Recording", frozen)]
pub struct Recording {
    reader: Mutex<RecordingReader>,
    path: PathBuf,
    frame_count: u64,
}

impl Recording {
    fn with_reader<T>(&self, f: impl FnOnce(&mut RecordingReader) -> T) -> PyResult<T> {
        let mut guard = self
            .reader
            .lock()
            .map_err(|_| RecordingError::new_err("the reader failed earlier"))?;
        Ok(f(&mut guard))
    }
}

/// An (n, k) float64 array of `rows`.
fn matrix<'py, const K: usize>(
    py: Python<'py>,
    rows: Vec<[f64; K]>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    Ok(PyArray1::from_vec(py, flat).reshape([n, K])?.into_any())
}

/// The frame's fields as a dict of numpy arrays and numbers.
fn frame_dict<'py>(py: Python<'py>, f: ParticleFrame) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("step", f.step)?;
    d.set_item("time", f.time)?;
    d.set_item(
        "box_edges",
        PyArray1::from_vec(py, f.box_edges.to_array().to_vec()),
    )?;
    d.set_item("ids", PyArray1::from_vec(py, f.ids))?;
    d.set_item(
        "positions",
        matrix(py, f.positions.iter().map(|p| p.to_array()).collect())?,
    )?;
    d.set_item(
        "orientations",
        matrix(py, f.orientations.iter().map(|q| q.to_array()).collect())?,
    )?;
    d.set_item("radii", PyArray1::from_vec(py, f.radii))?;
    d.set_item("half_lengths", PyArray1::from_vec(py, f.half_lengths))?;
    let n = f.rng_states.len();
    let rng: Vec<u64> = f.rng_states.into_iter().flatten().collect();
    d.set_item("rng_states", PyArray1::from_vec(py, rng).reshape([n, 4])?)?;
    d.set_item("status_json", f.status_json)?;
    Ok(d)
}

fn message_tuple<'py>(py: Python<'py>, m: RawMessage) -> PyResult<Bound<'py, PyTuple>> {
    PyTuple::new(
        py,
        [
            m.topic.into_pyobject(py)?.into_any(),
            m.schema_name.into_pyobject(py)?.into_any(),
            m.channel_id.into_pyobject(py)?.into_any(),
            m.sequence.into_pyobject(py)?.into_any(),
            m.log_time_ns.into_pyobject(py)?.into_any(),
            m.publish_time_ns.into_pyobject(py)?.into_any(),
            PyBytes::new(py, &m.data).into_any(),
        ],
    )
}

#[pymethods]
impl Recording {
    /// The file's path.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// Number of complete `/state` frames (from the summary section, or counted by the scan
    /// of a file without one).
    #[getter]
    fn frame_count(&self) -> u64 {
        self.frame_count
    }

    /// Size of the file \[bytes\].
    #[getter]
    fn file_bytes(&self) -> PyResult<u64> {
        self.with_reader(|r| r.file_bytes())
    }

    /// `None` for a complete file; else why it ends early (a killed run).
    #[getter]
    fn truncated(&self) -> PyResult<Option<String>> {
        self.with_reader(|r| r.truncated().map(str::to_string))
    }

    /// `None` unless a damaged record ends the readable part, or bytes follow the footer.
    #[getter]
    fn damaged(&self) -> PyResult<Option<String>> {
        self.with_reader(|r| {
            r.damage().map(|e| e.to_string()).or_else(|| {
                r.trailing_bytes()
                    .map(|(at, count)| trailing_message(at, count))
            })
        })
    }

    /// The run's metadata as a dict (None when the file has no `magsep` record).
    #[getter]
    fn metadata<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let meta = self.with_reader(|r| r.metadata().cloned())?;
        meta.map(|m| {
            let v = serde_json::to_value(&m).map_err(|e| RecordingError::new_err(e.to_string()))?;
            json_value(py, &v)
        })
        .transpose()
    }

    /// The run's summary as a dict (None when the file has none: a killed run).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let text = self.with_reader(|r| r.summary_json().map(str::to_string))?;
        text.map(|t| from_json(py, &t)).transpose()
    }

    /// Every metadata record: a list of (name, dict of str).
    #[getter]
    fn metadata_records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let records = self.with_reader(|r| r.metadata_records().to_vec())?;
        let items = records
            .into_iter()
            .map(|r| (r.name, r.entries))
            .collect::<Vec<_>>();
        PyList::new(py, items)
    }

    /// The channels: a list of dicts (id, topic, schema_name, schema_encoding,
    /// message_encoding, message_count).
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let channels = self.with_reader(|r| r.channels())?;
        let list = PyList::empty(py);
        for c in channels {
            let d = PyDict::new(py);
            d.set_item("id", c.id)?;
            d.set_item("topic", c.topic)?;
            d.set_item("schema_name", c.schema_name)?;
            d.set_item("schema_encoding", c.schema_encoding)?;
            d.set_item("message_encoding", c.message_encoding)?;
            d.set_item("message_count", c.message_count)?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The schema of the channel on `topic`: a dict (name, encoding, data: bytes), or None.
    fn schema<'py>(&self, py: Python<'py>, topic: &str) -> PyResult<Option<Bound<'py, PyDict>>> {
        let schema = self.with_reader(|r| r.schema(topic))?;
        schema
            .map(|s| {
                let d = PyDict::new(py);
                d.set_item("name", s.name)?;
                d.set_item("encoding", s.encoding)?;
                d.set_item("data", PyBytes::new(py, &s.data))?;
                Ok(d)
            })
            .transpose()
    }

    /// Frame `index` (0-based) as a dict of numpy arrays, or None past the last frame.
    fn frame<'py>(&self, py: Python<'py>, index: u64) -> PyResult<Option<Bound<'py, PyDict>>> {
        let frame = py
            .detach(|| self.with_reader(|r| r.frame(index)))?
            .map_err(record_error)?;
        frame.map(|f| frame_dict(py, f)).transpose()
    }

    /// Number of units (chunks, loose messages) to pass to `unit_messages`.
    #[getter]
    fn unit_count(&self) -> PyResult<usize> {
        self.with_reader(|r| r.unit_count())
    }

    /// The messages on `topic` (all for None) in unit `unit`, as tuples (topic, schema_name,
    /// channel_id, sequence, log_time_ns, publish_time_ns, data); None past the last unit.
    #[pyo3(signature = (unit, topic=None))]
    fn unit_messages<'py>(
        &self,
        py: Python<'py>,
        unit: usize,
        topic: Option<&str>,
    ) -> PyResult<Option<Bound<'py, PyList>>> {
        let messages = py.detach(|| self.with_reader(|r| r.unit_messages(unit, topic)))?;
        let Some(messages) = messages else {
            // past the last unit: the damage that ended the file, if any
            return match self.with_reader(|r| r.damage().map(|e| e.to_string()))? {
                Some(e) => Err(RecordingError::new_err(e)),
                None => Ok(None),
            };
        };
        let messages = messages.map_err(record_error)?;
        let list = PyList::empty(py);
        for m in messages {
            list.append(message_tuple(py, m)?)?;
        }
        Ok(Some(list))
    }
}

/// Every frame of the recording at `path` read by the library's whole-file reader
/// ([`magsep_record::read_recording`], a linear scan checking every CRC), and its truncation
/// message: the reference the streaming [`Recording`] is tested against.
#[pyfunction]
pub fn read_recording_frames<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyList>, Option<String>)> {
    let rec = py
        .detach(|| magsep_record::read_recording(&path))
        .map_err(record_error)?;
    let list = PyList::empty(py);
    for f in rec.frames {
        list.append(frame_dict(py, f)?)?;
    }
    Ok((list, rec.truncated))
}

/// Open the recording at `path` (streamed; nothing but its summary or a scan is read now).
#[pyfunction]
pub fn open_recording(py: Python<'_>, path: PathBuf) -> PyResult<Recording> {
    let reader = py
        .detach(|| RecordingReader::open(&path))
        .map_err(record_error)?;
    let frame_count = reader
        .channels()
        .iter()
        .filter(|c| c.topic == STATE_TOPIC)
        .map(|c| c.message_count)
        .sum();
    Ok(Recording {
        reader: Mutex::new(reader),
        path,
        frame_count,
    })
}
