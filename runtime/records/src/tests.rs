use std::fs;
use std::path::Path;

use parquet::basic::{ConvertedType, Encoding, Type as PhysicalType};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::{Field, RowAccessor};

use super::writer::ROW_GROUP_ROWS;
use super::{ExportError, Format, ParquetTable, Table, Value, export, finish_run_records};
use crate::Field as CsvField;

/// Rows as the world writes them (`ryu`'s forms): NaN poses, an exponent, -0.0, LED bytes, an empty robot id.
const TRAJECTORY: &str = "tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive
0,0,fb0,-6.648643,2.9218712,-3.1213431,0,0,0,1
0,1,fb1,NaN,NaN,NaN,0,0,0,0
0,2,,0.25,-0.0,3.1415927,0,0,0,1
1,0,fb0,1.5e-7,-0.52377146,3.1415925,255,128,7,1
1,1,fb1,NaN,NaN,NaN,0,0,0,0
1,2,,1.0,2000000000.0,-1.5707964,0,0,255,0
";

const EVENTS: &str = "tick,robot,robot_id,event
0,1,fb1,fault:kill
1,0,fb0,Go
1,0,fb0,saw-obs
2,2,fb2,#7
3,9,,fault:down
4,1,fb1,join:refused
";

/// Broadcasts without a recipient, delivered messages without a reason, letters from and to the world.
const MESSAGES: &str = "tick,from,to,address,bytes,outcome,reason
1,0,1,one,12,delivered,
1,0,,all,3,dropped,nobody_in_range
2,world,3,one,8,delivered,
2,4,world,one,16,delivered,
3,2,5,within:0.5,4,dropped,out_of_range
3,1,4294967295,one,2,dropped,unknown_recipient
";

fn run_with(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, text) in files {
        fs::write(dir.path().join(name), text).expect("written");
    }
    dir
}

fn all_tables() -> tempfile::TempDir {
    run_with(&[
        ("trajectory.csv", TRAJECTORY),
        ("events.csv", EVENTS),
        ("messages.csv", MESSAGES),
    ])
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("listed")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn csv_to_parquet_to_csv_is_byte_identical_for_every_table() {
    let run = all_tables();
    let report = export(run.path(), Format::Parquet).expect("exported");
    let rows: Vec<u64> = report.files.iter().map(|f| f.rows).collect();
    assert_eq!(rows, [6, 6, 6]);
    assert!(
        report
            .files
            .iter()
            .all(|f| f.output.extension().is_some_and(|e| e == "parquet"))
    );

    for table in Table::ALL {
        fs::remove_file(run.path().join(table.csv_name())).expect("removed");
    }
    let back = export(run.path(), Format::Csv).expect("exported back");
    assert_eq!(back.files.len(), 3);
    for (name, text) in [
        ("trajectory.csv", TRAJECTORY),
        ("events.csv", EVENTS),
        ("messages.csv", MESSAGES),
    ] {
        assert_eq!(
            fs::read_to_string(run.path().join(name)).expect("read"),
            text,
            "{name}"
        );
    }
    // No temporary file left behind.
    assert_eq!(
        names_in(run.path()),
        [
            "events.csv",
            "events.parquet",
            "messages.csv",
            "messages.parquet",
            "trajectory.csv",
            "trajectory.parquet"
        ]
    );
}

#[test]
fn floats_in_every_form_come_back_as_written() {
    // Every form ryu writes: integers, fractions, small and large exponents, subnormals, infinities.
    let mut csv = String::from("tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive\n");
    let mut bits = 1u32;
    for tick in 0..3_000u64 {
        bits = bits.wrapping_mul(2_654_435_761).wrapping_add(12_345);
        let floats = [
            f32::from_bits(bits),
            f32::from_bits(bits >> 9),
            tick as f32 * 0.1,
        ];
        let [x, y, heading] = floats.map(|f| ryu::Buffer::new().format(f).to_owned());
        csv += &format!(
            "{tick},{},r{},{x},{y},{heading},1,2,3,1\n",
            tick % 7,
            tick % 7
        );
    }
    csv += "3000,0,r0,inf,-inf,NaN,0,0,0,0\n";
    let run = run_with(&[("trajectory.csv", &csv)]);
    export(run.path(), Format::Parquet).expect("exported");
    fs::remove_file(run.path().join("trajectory.csv")).expect("removed");
    export(run.path(), Format::Csv).expect("exported back");
    assert_eq!(
        fs::read_to_string(run.path().join("trajectory.csv")).expect("read"),
        csv
    );
}

#[test]
fn a_header_only_file_gives_an_empty_table_and_back() {
    let header = "tick,robot,robot_id,event\n";
    let run = run_with(&[("events.csv", header)]);
    let report = export(run.path(), Format::Parquet).expect("exported");
    assert_eq!(report.files[0].rows, 0);
    fs::remove_file(run.path().join("events.csv")).expect("removed");
    export(run.path(), Format::Csv).expect("exported back");
    assert_eq!(
        fs::read_to_string(run.path().join("events.csv")).expect("read"),
        header
    );
}

#[test]
fn the_parquet_files_have_typed_columns_that_the_row_reader_reads() {
    let run = all_tables();
    export(run.path(), Format::Parquet).expect("exported");

    let reader = SerializedFileReader::try_from(run.path().join("trajectory.parquet").as_path())
        .expect("a Parquet file");
    let schema = reader.metadata().file_metadata().schema_descr();
    let types: Vec<(String, PhysicalType, ConvertedType)> = schema
        .columns()
        .iter()
        .map(|c| (c.name().to_owned(), c.physical_type(), c.converted_type()))
        .collect();
    use ConvertedType as C;
    use PhysicalType as P;
    let expected = [
        ("tick", P::INT64, C::UINT_64),
        ("robot", P::INT32, C::UINT_32),
        ("robot_id", P::BYTE_ARRAY, C::UTF8),
        ("x", P::FLOAT, C::NONE),
        ("y", P::FLOAT, C::NONE),
        ("heading", P::FLOAT, C::NONE),
        ("led_r", P::INT32, C::UINT_8),
        ("led_g", P::INT32, C::UINT_8),
        ("led_b", P::INT32, C::UINT_8),
        ("alive", P::BOOLEAN, C::NONE),
    ]
    .map(|(name, physical, converted)| (name.to_owned(), physical, converted));
    assert_eq!(types, expected);
    let robot_id = reader.metadata().row_group(0).column(2);
    assert!(robot_id.encodings().any(|e| e == Encoding::RLE_DICTIONARY));
    assert_eq!(robot_id.compression(), parquet::basic::Compression::SNAPPY);

    let rows: Vec<_> = reader
        .get_row_iter(None)
        .expect("rows")
        .collect::<Result<_, _>>()
        .expect("read");
    assert_eq!(rows.len(), 6);
    let row = &rows[3];
    assert_eq!(row.get_ulong(0).expect("tick"), 1);
    assert_eq!(row.get_uint(1).expect("robot"), 0);
    assert_eq!(row.get_string(2).expect("robot_id"), "fb0");
    assert_eq!(row.get_float(3).expect("x"), 1.5e-7);
    assert_eq!(row.get_float(4).expect("y"), -0.523_771_46);
    assert_eq!(row.get_ubyte(6).expect("led_r"), 255);
    assert_eq!(row.get_ubyte(8).expect("led_b"), 7);
    assert!(row.get_bool(9).expect("alive"));
    // A robot out of the run: NaN, not null.
    assert!(rows[1].get_float(3).expect("x").is_nan());
    assert!(!rows[1].get_bool(9).expect("alive"));

    let reader = SerializedFileReader::try_from(run.path().join("messages.parquet").as_path())
        .expect("a Parquet file");
    let rows: Vec<Vec<Field>> = reader
        .get_row_iter(None)
        .expect("rows")
        .map(|row| {
            row.expect("read")
                .into_columns()
                .into_iter()
                .map(|(_, f)| f)
                .collect()
        })
        .collect();
    let to: Vec<&Field> = rows.iter().map(|row| &row[2]).collect();
    assert_eq!(to[0], &Field::UInt(1));
    assert_eq!(to[1], &Field::Null);
    assert_eq!(to[3], &Field::UInt(swarm_contract::mail::TO_WORLD));
    assert_eq!(rows[2][1], Field::UInt(swarm_contract::mail::FROM_WORLD));
    assert_eq!(rows[0][6], Field::Null);
    assert_eq!(rows[1][6], Field::Str("nobody_in_range".into()));
    assert_eq!(rows[4][3], Field::Str("within:0.5".into()));
    assert_eq!(rows[4][4], Field::UShort(4));
}

fn csv_error(name: &str, text: impl AsRef<[u8]>) -> (u64, String) {
    let run = tempfile::tempdir().expect("temp dir");
    fs::write(run.path().join(name), text).expect("written");
    match export(run.path(), Format::Parquet) {
        Err(ExportError::Csv { path, line, what }) => {
            assert_eq!(path, run.path().join(name));
            // The failed conversion leaves nothing behind.
            assert_eq!(names_in(run.path()), [name]);
            (line, what)
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_malformed_row_names_its_line() {
    let bad = |line: &str| format!("{}{line}\n", EVENTS);
    let (line, what) = csv_error("events.csv", bad("5,1,fb1"));
    assert_eq!((line, what.as_str()), (8, "3 fields, expected 4"));
    let (line, what) = csv_error("events.csv", bad("5,1,fb,1,Go"));
    assert_eq!((line, what.as_str()), (8, "5 fields, expected 4"));
    let (line, what) = csv_error("events.csv", bad("-5,1,fb1,Go"));
    assert_eq!(line, 8);
    assert!(what.starts_with("column `tick`: `-5`"), "{what}");

    let traj = |line: &str| format!("{TRAJECTORY}{line}\n");
    let (line, what) = csv_error("trajectory.csv", traj("2,0,fb0,0.5,x,0.1,0,0,0,1"));
    assert_eq!(line, 8);
    assert!(what.starts_with("column `y`: `x`"), "{what}");
    let (_, what) = csv_error("trajectory.csv", traj("2,0,fb0,0.5,0.5,0.1,256,0,0,1"));
    assert_eq!(what, "column `led_r`: 256 does not fit in 8 bits");
    let (_, what) = csv_error("trajectory.csv", traj("2,0,fb0,0.5,0.5,0.1,0,0,0,2"));
    assert_eq!(what, "column `alive`: not 0 or 1");
    let mut not_utf8 = traj("2,0,fb0,0.5,0.5,0.1,0,0,0,1").into_bytes();
    let at = not_utf8.len() - 22;
    not_utf8[at] = 0xff;
    let (_, what) = csv_error("trajectory.csv", not_utf8);
    assert!(what.starts_with("column `robot_id`: not UTF-8"), "{what}");

    let (line, what) = csv_error(
        "messages.csv",
        format!("{MESSAGES}4,0,4294967294,one,2,delivered,\n"),
    );
    assert_eq!(line, 8);
    assert_eq!(
        what,
        "column `to`: 4294967294 is the world's number, written `world`"
    );
    let (_, what) = csv_error("messages.csv", format!("{MESSAGES}4,,1,one,2,delivered,\n"));
    assert!(what.starts_with("column `from`"), "{what}");
}

#[test]
fn a_wrong_header_a_cut_line_or_an_endless_line_is_an_error() {
    let (line, what) = csv_error("events.csv", "tick,robot,event\n1,0,Go\n");
    assert_eq!(line, 1);
    assert_eq!(
        what,
        "the header is `tick,robot,event`, expected `tick,robot,robot_id,event`"
    );
    let (line, what) = csv_error("events.csv", "");
    assert_eq!(
        (line, what.as_str()),
        (0, "the file is empty: no header line")
    );
    let (line, what) = csv_error("events.csv", format!("{EVENTS}5,1,fb1,G"));
    assert_eq!(line, 8);
    assert!(what.starts_with("cut short"), "{what}");
    let endless = format!("{EVENTS}{}", "x".repeat(super::csv_lines::MAX_LINE + 10));
    let (line, what) = csv_error("events.csv", endless);
    assert_eq!(line, 8);
    assert!(what.starts_with("longer than"), "{what}");
}

fn parquet_error(name: &str, bytes: &[u8]) -> ExportError {
    let run = tempfile::tempdir().expect("temp dir");
    fs::write(run.path().join(name), bytes).expect("written");
    let error = export(run.path(), Format::Csv).expect_err("refused");
    assert_eq!(names_in(run.path()), [name], "nothing written");
    error
}

fn parquet_of(name: &str, text: &str) -> Vec<u8> {
    let run = run_with(&[(name, text)]);
    export(run.path(), Format::Parquet).expect("exported");
    let parquet = Path::new(name).with_extension("parquet");
    fs::read(run.path().join(parquet)).expect("read")
}

#[test]
fn a_truncated_or_foreign_parquet_file_is_an_error_naming_it() {
    let events = parquet_of("events.csv", EVENTS);
    for cut in [0, 4, events.len() / 2, events.len() - 9, events.len() - 1] {
        let error = parquet_error("events.parquet", &events[..cut]);
        assert!(
            matches!(&error, ExportError::Parquet { path, .. } if path.ends_with("events.parquet")),
            "{error}"
        );
    }
    let error = parquet_error("events.parquet", b"tick,robot,robot_id,event\n");
    assert!(
        error.to_string().contains("not a readable Parquet file"),
        "{error}"
    );

    // The events table where the trajectory is expected.
    let error = parquet_error("trajectory.parquet", &events);
    assert!(
        error
            .to_string()
            .ends_with("4 columns, expected the 10 of trajectory.csv"),
        "{error}"
    );
    let messages = parquet_of("messages.csv", MESSAGES);
    let error = parquet_error("events.parquet", &messages);
    assert!(error.to_string().contains("7 columns"), "{error}");
}

#[test]
fn corrupted_parquet_bytes_never_panic() {
    let events = parquet_of("events.csv", EVENTS);
    let run = tempfile::tempdir().expect("temp dir");
    let path = run.path().join("events.parquet");
    for position in 0..events.len() {
        for flip in [0x01u8, 0x80, 0xff] {
            let mut bytes = events.clone();
            bytes[position] ^= flip;
            fs::write(&path, &bytes).expect("written");
            // An error or, where the flipped byte does not matter, a conversion: never a panic.
            if export(run.path(), Format::Csv).is_ok() {
                fs::remove_file(run.path().join("events.csv")).expect("removed");
            }
        }
    }
}

#[test]
fn a_missing_or_empty_run_folder_is_an_error() {
    let run = tempfile::tempdir().expect("temp dir");
    let missing = run.path().join("nope");
    let error = export(&missing, Format::Parquet).expect_err("refused");
    assert_eq!(
        error.to_string(),
        format!("{}: no such run folder", missing.display())
    );
    let error = export(run.path(), Format::Csv).expect_err("refused");
    assert_eq!(
        error.to_string(),
        format!(
            "{}: no record file to export as CSV (looked for trajectory.parquet, events.parquet, messages.parquet)",
            run.path().display()
        )
    );
}

#[test]
fn row_groups_end_with_the_tick_that_fills_them_and_know_their_ticks() {
    const PER_TICK: usize = 100;
    let rows = ROW_GROUP_ROWS + 250;
    let mut csv = String::from("tick,robot,robot_id,event\n");
    for row in 0..rows {
        csv += &format!(
            "{},{},e{},Go\n",
            row / PER_TICK,
            row % PER_TICK,
            row % PER_TICK
        );
    }
    let run = run_with(&[("events.csv", &csv)]);
    export(run.path(), Format::Parquet).expect("exported");
    let table = ParquetTable::open(Table::Events, &run.path().join("events.parquet"))
        .expect("a Parquet file of the table");
    let first = ROW_GROUP_ROWS.div_ceil(PER_TICK) * PER_TICK;
    let groups: Vec<u64> = (0..table.row_groups()).map(|g| table.rows(g)).collect();
    assert_eq!(groups, [first as u64, (rows - first) as u64]);
    let last_tick = ((rows - 1) / PER_TICK) as u64;
    let first_group_end = (first / PER_TICK - 1) as u64;
    assert_eq!(table.ticks(0), Some((0, first_group_end)));
    assert_eq!(table.ticks(1), Some((first_group_end + 1, last_tick)));
    let mut seen = Vec::new();
    table
        .read_row_group(1, |row, values| {
            seen.push((row, format!("{:?} {:?}", values[0], values[1])));
            Ok(())
        })
        .expect("read");
    assert_eq!(seen.len(), rows - first);
    let expected = (Value::Int64(first_group_end as i64 + 1), Value::Int32(0));
    assert_eq!(seen[0], (0, format!("{:?} {:?}", expected.0, expected.1)));
    fs::remove_file(run.path().join("events.csv")).expect("removed");
    export(run.path(), Format::Csv).expect("exported back");
    assert!(fs::read_to_string(run.path().join("events.csv")).expect("read") == csv);
}

#[test]
fn finishing_a_run_leaves_parquet_files_only() {
    let run = all_tables();
    let csv: Vec<Vec<u8>> = Table::ALL
        .iter()
        .map(|t| fs::read(run.path().join(t.csv_name())).expect("read"))
        .collect();
    let report = finish_run_records(run.path()).expect("finished");
    assert_eq!(report.files.len(), 3);
    assert_eq!(
        names_in(run.path()),
        ["events.parquet", "messages.parquet", "trajectory.parquet"]
    );
    export(run.path(), Format::Csv).expect("exported back");
    for (table, original) in Table::ALL.iter().zip(&csv) {
        assert!(&fs::read(run.path().join(table.csv_name())).expect("read") == original);
    }
}

#[test]
fn finishing_keeps_the_parquet_files_the_world_completed_and_drops_its_unfinished_ones() {
    let run = all_tables();
    export(run.path(), Format::Parquet).expect("exported");
    let completed = fs::read(run.path().join("trajectory.parquet")).expect("read");
    for table in ["events", "messages"] {
        fs::remove_file(run.path().join(format!("{table}.parquet"))).expect("removed");
    }
    // What a world killed while writing leaves, and a file that only looks alike.
    fs::write(run.path().join(".events.parquet.4242.tmp"), b"PAR1").expect("written");
    fs::write(run.path().join(".events.parquet.notes"), b"kept").expect("written");
    let report = finish_run_records(run.path()).expect("finished");
    let converted: Vec<String> = report
        .files
        .iter()
        .map(|f| {
            f.output
                .file_name()
                .expect("name")
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(converted, ["events.parquet", "messages.parquet"]);
    assert!(fs::read(run.path().join("trajectory.parquet")).expect("read") == completed);
    assert_eq!(
        names_in(run.path()),
        [
            ".events.parquet.notes",
            "events.parquet",
            "messages.parquet",
            "trajectory.parquet"
        ]
    );
}

#[test]
fn a_run_whose_records_cannot_be_finished_keeps_its_csv_files_alone() {
    let run = all_tables();
    fs::write(
        run.path().join("events.csv"),
        "tick,robot,robot_id,event\n1,x,e0,Go\n",
    )
    .expect("written");
    let error = finish_run_records(run.path()).expect_err("a malformed row");
    assert!(error.to_string().contains("events.csv, line 2"), "{error}");
    assert_eq!(
        names_in(run.path()),
        ["events.csv", "messages.csv", "trajectory.csv"]
    );
}

/// Converts a real run both ways and prints sizes and times: `SWARM_EXPORT_BENCH_DIR=<run folder> cargo test
/// -p swarm-records --release tests::export_a_real_run -- --ignored --nocapture`. The run folder is not
/// touched: its CSV files are copied into a temporary folder first.
#[test]
#[ignore = "needs SWARM_EXPORT_BENCH_DIR, a run folder"]
fn export_a_real_run() {
    let source = std::env::var_os("SWARM_EXPORT_BENCH_DIR").expect("SWARM_EXPORT_BENCH_DIR");
    let run = tempfile::tempdir().expect("temp dir");
    let originals = tempfile::tempdir().expect("temp dir");
    for table in Table::ALL {
        let csv = Path::new(&source).join(table.csv_name());
        if csv.exists() {
            fs::copy(&csv, run.path().join(table.csv_name())).expect("copied");
        }
    }
    for file in export(run.path(), Format::Parquet).expect("exported").files {
        println!("{file}");
        fs::rename(
            &file.source,
            originals
                .path()
                .join(file.source.file_name().expect("name")),
        )
        .expect("moved");
    }
    for file in export(run.path(), Format::Csv)
        .expect("exported back")
        .files
    {
        println!("{file}");
        let name = file.output.file_name().expect("name");
        let same = fs::read(&file.output).expect("read")
            == fs::read(originals.path().join(name)).expect("read");
        assert!(same, "{} differs from the original", file.output.display());
    }
}

/// The CSV text the world's recorder writes for `field`.
fn csv_text(field: CsvField<'_>) -> String {
    match field {
        CsvField::Int(v) => itoa::Buffer::new().format(v).to_owned(),
        CsvField::Float(v) => ryu::Buffer::new().format(v).to_owned(),
        CsvField::Text(text) => text.to_owned(),
    }
}

#[test]
fn a_field_has_the_value_its_csv_text_reads_back_as_in_every_column() {
    let negative_nan = f32::from_bits(0xffc0_0001);
    let fields = [
        CsvField::Int(0),
        CsvField::Int(1),
        CsvField::Int(255),
        CsvField::Int(256),
        CsvField::Int(65_536),
        CsvField::Int(u64::from(u32::MAX) - 1),
        CsvField::Int(u64::from(u32::MAX)),
        CsvField::Int(u64::MAX),
        CsvField::Float(0.25),
        CsvField::Float(-0.0),
        CsvField::Float(1.5e-7),
        CsvField::Float(f32::NAN),
        CsvField::Float(negative_nan),
        CsvField::Text(""),
        CsvField::Text("world"),
        CsvField::Text("fb0"),
        CsvField::Text("within:0.5"),
    ];
    let mut accepted = 0;
    for table in Table::ALL {
        for column in table.columns() {
            for field in fields {
                let text = csv_text(field);
                let direct = column.value_of(field).map(|v| format!("{v:?}"));
                let read_back = column.parse(text.as_bytes()).map(|v| format!("{v:?}"));
                // A field taken directly has the value its text reads back as (fields a column takes
                // neither way, e.g. a float in `tick`, are refused by both or only by the direct path).
                if let Ok(direct) = &direct {
                    assert_eq!(
                        Ok(direct),
                        read_back.as_ref(),
                        "{field:?} in `{}` of {table:?}",
                        column.name
                    );
                    accepted += 1;
                }
            }
        }
    }
    assert!(accepted > 0);
    // And every column takes the fields the recorder writes into it.
    let written: [(Table, &[CsvField<'_>]); 3] = [
        (
            Table::Trajectory,
            &[
                CsvField::Int(3),
                CsvField::Int(1),
                CsvField::Text("fb1"),
                CsvField::Float(0.5),
                CsvField::Float(f32::NAN),
                CsvField::Float(-3.0),
                CsvField::Int(255),
                CsvField::Int(0),
                CsvField::Int(7),
                CsvField::Int(1),
            ],
        ),
        (
            Table::Events,
            &[
                CsvField::Int(3),
                CsvField::Int(1),
                CsvField::Text("fb1"),
                CsvField::Text("#7"),
            ],
        ),
        (
            Table::Messages,
            &[
                CsvField::Int(3),
                CsvField::Text("world"),
                CsvField::Text(""),
                CsvField::Text("within:0.5"),
                CsvField::Int(12),
                CsvField::Text("dropped"),
                CsvField::Text("lost"),
            ],
        ),
    ];
    for (table, row) in written {
        for (column, &field) in table.columns().iter().zip(row) {
            assert!(
                column.value_of(field).is_ok(),
                "{field:?} in `{}` of {table:?}",
                column.name
            );
        }
    }
}
