"""Build vn100_F00379-F00383.csv from the parsed VN-100 files of jerabaul29/LoggerWavesInIce.

Source: commit 3d32dd474699ede5973df1e7da1cbf378c1bacd7,
Logger_GPS_SD_VN_Binary_output_Parser/Example_parsed_data/F0037[9]_B, F0038[0-3]_B (VN-100
records, 29 comma-separated floats a line after one header line) and the matching *_Bt files
(Arduino millis() of each record, one a line). Record i of *_B belongs to line i of *_Bt.
Records that are not 29 values (the parser's placeholder "0.000000e+00," for a frame that
failed its checksum) are dropped with their time stamp. Values are copied as written (no
reformatting); only columns 3-9 (Acc, Gyro, Temp) are kept.

Usage: python3 convert.py SRC_DIR   (SRC_DIR holds the ten original files)
"""
import os
import sys

FILES = ["F00379", "F00380", "F00381", "F00382", "F00383"]
OUT = "vn100_F00379-F00383.csv"


def main(src):
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, OUT), "w", newline="\n") as out:
        out.write("millis,GyroX,GyroY,GyroZ,AccX,AccY,AccZ,Temp\n")
        for name in FILES:
            with open(os.path.join(src, name + "_B")) as f:
                recs = f.read().splitlines()[1:]
            with open(os.path.join(src, name + "_Bt")) as f:
                stamps = f.read().splitlines()
            assert len(recs) == len(stamps), name
            for rec, ms in zip(recs, stamps, strict=True):
                v = rec.strip().rstrip(",").split(",")
                if len(v) != 29:
                    continue
                # 0-2 Mag, 3-5 Acc, 6-8 Gyro, 9 Temp
                out.write(",".join([ms.strip(), *v[6:9], *v[3:6], v[9]]) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
